// Resolve to the display: constant grids resolve to constants (φ wrap, ρ clamp, coverage),
// and a smooth analytic image survives the round trip display -> grid -> display within
// 0.5 dB of the budget-limited ideal.
#include <cmath>

#include "fovea/core/metrics.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

namespace {

// Smooth test image: a few low-frequency sinusoids (k in radians per pixel).
struct Wave {
  double kx, ky, phase, amp;
};
constexpr Wave kWaves[] = {{0.031, 0.012, 0.3, 0.2}, {-0.017, 0.041, 1.1, 0.15}, {0.052, -0.023, 2.0, 0.1}};

double analytic(glm::dvec2 p, double sigma) {
  double v = 0.5;
  for (const Wave& w : kWaves)
    v += w.amp * std::exp(-0.5 * (w.kx * w.kx + w.ky * w.ky) * sigma * sigma) *
         std::sin(w.kx * p.x + w.ky * p.y + w.phase);
  return v;
}

class Resolve : public GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    scene_ = renderer::load_scene("cornell");
    gs_ = std::make_unique<renderer::GpuScene>(ctx(), scene_);
  }
  renderer::Scene scene_;
  std::unique_ptr<renderer::GpuScene> gs_;
};

std::vector<glm::vec4> grid_of(const core::SampleDistribution& d, double (*f)(glm::dvec2, double)) {
  std::vector<glm::vec4> g(std::size_t(d.padded_columns()) * d.padded_rows(), glm::vec4(0));
  for (int r = 0; r < d.padded_rows(); ++r)
    for (int c = 0; c < d.padded_columns(); ++c) {
      const auto s = d.sample_at(c, r, {0, 0});
      if (s.flags & (fovea::shaders::kCellClipped | fovea::shaders::kCellPadding)) continue;
      const float v = float(f({s.screen_x, s.screen_y}, 0.0));
      g[std::size_t(r) * d.padded_columns() + c] = {v, v, v, 1};
    }
  return g;
}

}  // namespace

TEST_F(Resolve, ConstantGridResolvesToTheConstantEverywhere) {
  const core::DisplayPreset display = fovea::test::display_of_size(96, 108);
  reconstruct::ReconSettings s;
  s.blur = false;
  pipeline::FramePipeline p(ctx(), *gs_, core::stereo_views(display), {}, s, {}, true);
  const auto& d = p.distribution(core::Eye::Left);
  const core::Image img = pipeline::testing::resolve_grid(p, core::Eye::Left, grid_of(d, [](glm::dvec2, double) { return 0.75; }), false);
  for (const auto& px : img.pixels) ASSERT_NEAR(px.x, 0.75f, 1e-5f);
}

TEST_F(Resolve, RoundTripWithinHalfDecibelOfTheBudgetLimitedIdeal) {
  const core::DisplayPreset display = core::load_display("small");
  reconstruct::ReconSettings s;
  s.blur = false;
  pipeline::FramePipeline p(ctx(), *gs_, core::stereo_views(display), {}, s, {}, true);
  const auto& d = p.distribution(core::Eye::Left);
  const core::Image img = pipeline::testing::resolve_grid(p, core::Eye::Left, grid_of(d, analytic), false);
  // The ideal: the image low-passed at the grid's local sample spacing h (Gaussian σ = h/2),
  // i.e. what any reconstruction from samples that sparse can keep.
  core::Image truth(display.width, display.height), ideal = truth;
  for (int y = 0; y < display.height; ++y)
    for (int x = 0; x < display.width; ++x) {
      const glm::dvec2 px{x + 0.5, y + 0.5};
      const double spp = d.samples_per_pixel(px);
      const double h = spp > 0 ? std::max(1.0, 1.0 / std::sqrt(spp)) : 1.0;
      const float t = float(analytic(px, 0)), i = float(analytic(px, 0.5 * h));
      truth.at(x, y) = {t, t, t, 1};
      ideal.at(x, y) = {i, i, i, 1};
    }
  const double got = core::psnr(img, truth), best = core::psnr(ideal, truth);
  std::printf("round trip %.2f dB, ideal %.2f dB\n", got, best);
  EXPECT_GE(got, best - 0.5);
}
