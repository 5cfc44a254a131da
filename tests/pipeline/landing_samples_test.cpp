// A new fovea's first frames trace more samples (ReconSettings::landing_spp,
// docs/reconstruction.md "A 32° gaze step"): after a gaze jump of 32° the cells within the
// fovea (plus the margin) enter Phase I with landing_spp samples for kLandingFrames frames,
// and one sample again after; the periphery always with one. On the landing frame the new
// fovea's history (the periphery's, resampled) counts for ReconSettings::landing_history
// samples at most. Phase I's sample counts show both, against the same frames with
// landing_spp 1 and with the history's full count.
#include <algorithm>
#include <cmath>
#include <vector>

#include "fovea/core/acuity.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace landing_samples {

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

struct Counts {
  double fovea = 0, periphery = 0;  // median Phase I sample count of the direct light
};

constexpr std::uint32_t kSettle = 6;  // frames at −16° before the jump

// Phase I's counts per frame from the landing (frame kSettle at +16°, after kSettle at −16°).
std::vector<Counts> counts_after_landing(fovea::gpu::Context& ctx, std::uint32_t landing_spp,
                                         float landing_history = reconstruct::ReconSettings{}.landing_history) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  const renderer::GpuScene gs(ctx, scene);
  const core::DisplayPreset display = fovea::test::display_of_size(128, 144);
  reconstruct::ReconSettings s;
  s.landing_spp = landing_spp;
  s.landing_history = landing_history;
  pipeline::FramePipeline p(ctx, gs, core::stereo_views(display), {}, s, {}, /*mono=*/true);
  const auto& d = p.distribution(core::Eye::Left);
  const auto poses = core::eye_poses(scene.camera, display);
  std::vector<Counts> out;
  for (std::uint32_t f = 0; f < kSettle + reconstruct::kLandingFrames + 2; ++f) {
    const glm::dvec3 g = fovea::test::horizontal_gaze(f < kSettle ? -16 : 16);
    p.render(poses, {g, g}, f);
    if (f < kSettle) continue;
    const auto acc = pipeline::testing::grid_buffer(p, core::Eye::Left, pipeline::testing::GridBuffer::AccDirect);
    std::vector<double> fovea, periphery;
    for (int r = 0; r < d.rows(); ++r)
      for (int c = 0; c < d.columns(); ++c) {
        const auto cell = d.sample(c, r);
        if (cell.flags != 0) continue;
        const double n = acc[std::size_t(r) * d.padded_columns() + c].w;
        if (cell.ecc_deg <= core::acuity::kFoveaDeg) fovea.push_back(n);
        else if (cell.ecc_deg > 15) periphery.push_back(n);
      }
    out.push_back({median(fovea), median(periphery)});
  }
  return out;
}

TEST_F(GpuTest, ANewFoveaTracesMoreSamplesInItsFirstFrames) {
  const std::vector<Counts> boosted = counts_after_landing(ctx(), 4);
  const std::vector<Counts> plain = counts_after_landing(ctx(), 1);
  for (std::size_t k = 0; k < boosted.size(); ++k)
    std::printf("frame %zu after the landing: fovea count %g (landing_spp 1: %g), periphery %g (%g)\n", k + 1,
                boosted[k].fovea, plain[k].fovea, boosted[k].periphery, plain[k].periphery);
  // Each boosted frame adds 4 samples to the fovea's count, a plain one 1 (on this small
  // raster the fovea keeps the history from before the jump, capped: both start from it).
  for (std::uint32_t k = 0; k < reconstruct::kLandingFrames; ++k)
    EXPECT_NEAR(boosted[k].fovea - plain[k].fovea, 3.0 * (k + 1), 0.5) << "frame " << k + 1;
  // After the window: one sample a frame again.
  const std::size_t last = boosted.size() - 1;
  EXPECT_NEAR(boosted[last].fovea - boosted[last - 1].fovea, 1.0, 0.5);
  // The periphery never takes the extra samples.
  for (std::size_t k = 0; k < boosted.size(); ++k) EXPECT_EQ(boosted[k].periphery, plain[k].periphery);
}

TEST_F(GpuTest, ALandedFoveaCountsItsOldHistoryForAFewSamples) {
  const float cap = reconstruct::ReconSettings{}.landing_history;
  const std::vector<Counts> capped = counts_after_landing(ctx(), 8);
  const std::vector<Counts> full = counts_after_landing(ctx(), 8, 1e9f);
  for (std::size_t k = 0; k < capped.size(); ++k)
    std::printf("frame %zu after the landing: fovea count %g (history's full count: %g), periphery %g (%g)\n",
                k + 1, capped[k].fovea, full[k].fovea, capped[k].periphery, full[k].periphery);
  ASSERT_GE(cap, 1.0f);
  ASSERT_LT(cap, float(kSettle));
  // The landing frame: the kSettle frames before count for `cap` samples, then 8 of its own.
  EXPECT_NEAR(full[0].fovea, kSettle + 8.0, 0.5);
  EXPECT_NEAR(capped[0].fovea, cap + 8.0, 0.5);
  // Only that frame is capped: the next ones add their samples to either.
  for (std::size_t k = 1; k < capped.size(); ++k)
    EXPECT_NEAR(full[k].fovea - capped[k].fovea, kSettle - cap, 0.5) << "frame " << k + 1;
  // The periphery's history is never capped.
  for (std::size_t k = 0; k < capped.size(); ++k) EXPECT_EQ(capped[k].periphery, full[k].periphery);
}

}  // namespace landing_samples
