// The optics LUT cache against direct evaluation (the reference).
#include "fovea/core/lens_lut.hpp"

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"

using namespace fovea::core;

namespace {

TEST(LensLut, NodesInsideTheEdgeEqualDirectEvaluation) {
  const Lens lens = Lens::for_eye(load_display("small"), Eye::Left);
  const LensLut lut(lens, 16);
  int inside = 0;
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i)
      for (int c = 0; c < 3; ++c) {
        const glm::dvec2 uv(i / 15.0, j / 15.0);
        const Lens::Channel& ch = lens.channel(c);
        if (glm::length((uv - ch.display_centre) * ch.to_radial) > ch.r_edge) continue;  // smooth continuation
        ++inside;
        const glm::dvec2 a = lut.source_uv(c, uv), b = lens.source_uv(c, uv);
        EXPECT_NEAR(a.x, b.x, 1e-12) << i << "," << j << " channel " << c;
        EXPECT_NEAR(a.y, b.y, 1e-12) << i << "," << j << " channel " << c;
      }
  EXPECT_GT(inside, 16 * 16);
  // The packed floats hold the same nodes at ((j·N + i)·3 + c)·2.
  const std::vector<float> p = lut.packed();
  ASSERT_EQ(p.size(), size_t(16 * 16 * 3 * 2));
  const glm::dvec2 n = lens.source_uv(2, {7 / 15.0, 9 / 15.0});
  EXPECT_FLOAT_EQ(p[((9 * 16 + 7) * 3 + 2) * 2], float(n.x));
  EXPECT_FLOAT_EQ(p[((9 * 16 + 7) * 3 + 2) * 2 + 1], float(n.y));
}

TEST(LensLut, RefusesBadSizes) {
  const Lens lens = Lens::for_eye(load_display("tiny"), Eye::Left);
  EXPECT_THROW(LensLut(lens, 1), InputError);
  EXPECT_THROW(LensLut(lens, 5000), InputError);
}

// The 128² cache's error over the visible panel, per preset, eye and channel; printed for
// docs/display-stage.md. Large panels are sampled every few pixels to keep the test fast.
TEST(LensLut, ErrorAgainstDirectEvaluationPerPreset) {
  struct Case {
    const char* preset;
    int stride;
  };
#ifdef FOVEA_SANITIZED_BUILD
  const Case cases[] = {{"tiny", 1}, {"small", 3}, {"fove0", 16}, {"vive", 16}, {"modern", 32}};
#else
  const Case cases[] = {{"tiny", 1}, {"small", 1}, {"fove0", 3}, {"vive", 3}, {"modern", 5}};
#endif
  for (const Case& k : cases) {
    const DisplayPreset d = load_display(k.preset);
    for (Eye eye : {Eye::Left, Eye::Right}) {
      const HiddenAreaMask mask(Lens::for_eye(d, eye));
      const LensLut lut(mask.lens());
      const auto err = measure_lut_error(lut, mask, k.stride);
      for (int c = 0; c < 3; ++c) {
        const LutError& e = err[size_t(c)];
        std::printf("%-6s %s %c: view px max %.4f mean %.5f | display px max %.4f mean %.5f (at uv %.3f,%.3f)\n",
                    k.preset, eye == Eye::Left ? "L" : "R", "rgb"[c], e.max_view_px, e.mean_view_px,
                    e.max_display_px, e.mean_display_px, e.worst_uv.x, e.worst_uv.y);
        EXPECT_GT(e.max_display_px, 0.0) << "a cache that is exact everywhere is not being measured";
        // A quarter of a display pixel at most, even on 2448-px panels (19 px per LUT cell).
        EXPECT_LT(e.max_display_px, 0.25) << k.preset << " channel " << c;
        EXPECT_LT(e.max_view_px, 0.25) << k.preset << " channel " << c;
        EXPECT_LT(e.mean_display_px, 0.05) << k.preset << " channel " << c;
      }
    }
  }
}

}  // namespace
