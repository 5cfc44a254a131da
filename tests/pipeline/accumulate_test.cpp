// Temporal accumulation through the previous frame's grid mapping: a static scene stays
// stable while the gaze sweeps (the grid moves under it every frame).
#include "fovea/core/metrics.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

TEST_F(GpuTest, AccumulationKeepsAStaticSceneStableWhileTheGazeSweeps) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
#ifdef FOVEA_SANITIZED_BUILD
  const core::DisplayPreset display = fovea::test::display_of_size(64, 72);
#else
  const core::DisplayPreset display = fovea::test::display_of_size(128, 144);
#endif
  reconstruct::ReconSettings s;
  s.denoiser = reconstruct::Denoiser::None;
  s.blur = false;
  // Jitter off: this measures the moving grid's resampling alone. With the default jitter the
  // frames also differ at edges by the sub-cell offsets (no TAA with denoiser none), with and
  // without history alike: the ratio below was 0.67 then.
  core::DistributionParams dp;
  dp.jitter = false;
  pipeline::FramePipeline with(ctx(), gs, core::stereo_views(display), dp, s, {}, true);
  pipeline::FramePipeline without(ctx(), gs, core::stereo_views(display), dp, s, {}, true);
  const auto poses = core::eye_poses(scene.camera, display);
  const int frames = 12;
  double te_with = 0, te_without = 0;
  core::Image prev_with, prev_without;
  for (int f = 0; f < frames; ++f) {
    const double a = (-15.0 + 30.0 * f / (frames - 1)) * M_PI / 180;  // 30° horizontal sweep
    const std::array<glm::dvec3, 2> gaze{glm::dvec3(std::sin(a), 0, -std::cos(a)), glm::dvec3(0, 0, -1)};
    with.render(poses, gaze, std::uint32_t(f));
    without.reset();
    without.render(poses, gaze, std::uint32_t(f));
    const core::Image iw = with.image(core::Eye::Left), io = without.image(core::Eye::Left);
    if (f > 0) te_with += core::temporal_error(prev_with, iw), te_without += core::temporal_error(prev_without, io);
    prev_with = iw, prev_without = io;
  }
  // History survived the moving grid: most samples hold many frames.
  const auto acc = pipeline::testing::grid_buffer(with, core::Eye::Left, pipeline::testing::GridBuffer::AccDirect);
  const auto samples = with.grid_samples(core::Eye::Left);
  double count = 0;
  long n = 0;
  for (std::size_t i = 0; i < acc.size(); ++i)
    if (samples[i].flags == 0) count += acc[i].w, ++n;
  std::printf("temporal error %.5f with history, %.5f without; mean count %.2f\n", te_with / (frames - 1),
              te_without / (frames - 1), count / double(n));
  // Smooth pursuit (2.7°/frame) keeps its history through the cell-size test (measured 12.00).
  EXPECT_GT(count / double(n), 0.9 * frames);
  EXPECT_LT(te_with, 0.65 * te_without);  // measured 0.54: EMA noise floor plus resampling of the moving grid
}

// The temporal error measured on the device (FramePipeline::enable_temporal_error, what
// `fovea render` reports without reading frames back) is core::temporal_error of the images
// it displayed, averaged over consecutive pairs, for both eyes; reset() does not restart it.
TEST_F(GpuTest, DeviceTemporalErrorIsTheHostOneOfTheDisplayedImages) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  // 70 pixels: rows end inside a 64-pixel run of recon_temporal.comp.
  const core::DisplayPreset display = fovea::test::display_of_size(70, 48);
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), {}, {});
  p.enable_temporal_error();
  const auto poses = core::eye_poses(scene.camera, display);
  std::array<core::Image, 2> prev;
  std::array<double, 2> host{0, 0};
  const int frames = 5;
  for (int f = 0; f < frames; ++f) {
    const double a = (-10.0 + 5.0 * f) * M_PI / 180;
    const glm::dvec3 g(std::sin(a), 0, -std::cos(a));
    if (f == 3) p.reset();
    p.render(poses, {g, g}, std::uint32_t(f));
    for (int e = 0; e < 2; ++e) {
      const core::Image img = p.image(core::Eye(e));
      if (f > 0) host[e] += core::temporal_error(prev[e], img);
      prev[e] = img;
    }
    if (f == 0) {
      EXPECT_EQ(p.temporal_error(core::Eye::Left), 0.0);
    }
  }
  for (int e = 0; e < 2; ++e) {
    const double expected = host[e] / (frames - 1);
    EXPECT_GT(expected, 0.0);
    EXPECT_NEAR(p.temporal_error(core::Eye(e)), expected, 1e-5 * expected) << "eye " << e;
  }
}
