// The peripheral blur follows the acuity model: σ(e) = √(ln 2 / 2) / π · MAR₀ / m(e)
// (reconstruct::blur_sigma_deg). The kernel's width is measured on the GPU from the blurred
// image of a single bright pixel (its second moment along each axis) and compared with the
// formula converted by the raster's local pixel size.
#include <cmath>

#include "fovea/core/acuity.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

TEST(BlurSigma, IsTheAcuityModelsResolutionLimit) {
  // MTF exp(−2π²σ²f²) = 1/2 at f = 1/MAR: σ = 0.1874·MAR; MAR(30°) = 1′ / m(30) = 0.2225°.
  EXPECT_NEAR(reconstruct::blur_sigma_deg(30), 0.0417, 0.0005);
  for (double e : {0.0, 10.0, 30.0, 60.0}) {
    const double mar = reconstruct::kMarFoveaDeg / core::acuity::m(e);
    const double s = reconstruct::blur_sigma_deg(e);
    EXPECT_NEAR(std::exp(-2 * M_PI * M_PI * s * s / (mar * mar)), 0.5, 1e-9) << e;
  }
}

TEST_F(GpuTest, BlurWidthFollowsTheAcuityModelAcrossEccentricities) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(640, 720);
  reconstruct::ReconSettings s;
  s.denoiser = reconstruct::Denoiser::None;
  // 16′ instead of 1′ scales every σ by 16, into whole pixels on this raster (1.7–13 px).
  s.blur_mar_fovea_deg = 16.0 / 60.0;
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), {}, s, {}, true);
  p.render(core::eye_poses(scene.camera, display.ipd_m), {glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)}, 0);
  const core::View v = p.view(core::Eye::Left);
  for (double e : {20.0, 30.0, 40.0, 45.0}) {
    const glm::dvec3 dir = glm::normalize(glm::dvec3(std::tan(e * M_PI / 180), 0, -1));
    const glm::dvec2 at = *v.dir_to_pixel(dir);
    const int x0 = int(at.x), y0 = int(at.y);
    core::Image img(v.width(), v.height());
    img.at(x0, y0) = glm::vec4(1.0f);
    const core::Image out = pipeline::testing::blur_image(p, core::Eye::Left, img);
    double sum = 0, mx = 0, my = 0;
    for (int y = 0; y < out.height; ++y)
      for (int x = 0; x < out.width; ++x) {
        const double w = out.at(x, y).x;
        sum += w, mx += w * (x - x0) * (x - x0), my += w * (y - y0) * (y - y0);
      }
    const glm::dvec2 c{x0 + 0.5, y0 + 0.5};
    const double e_px = core::angle_deg(v.pixel_to_dir(c), glm::dvec3(0, 0, -1));
    const double sigma_deg = reconstruct::blur_sigma_deg(e_px, s.blur_mar_fovea_deg);
    const double want_x = sigma_deg / core::angle_deg(v.pixel_to_dir(c), v.pixel_to_dir(c + glm::dvec2(1, 0)));
    const double want_y = sigma_deg / core::angle_deg(v.pixel_to_dir(c), v.pixel_to_dir(c + glm::dvec2(0, 1)));
    const double got_x = std::sqrt(mx / sum), got_y = std::sqrt(my / sum);
    std::printf("e %.1f deg: sigma x %.3f px (model %.3f), y %.3f px (model %.3f)\n", e_px, got_x, want_x, got_y,
                want_y);
    EXPECT_NEAR(sum, 1.0, 0.02) << e;  // weights renormalised: energy kept
    EXPECT_NEAR(got_x, want_x, 0.08 * want_x) << e;
    EXPECT_NEAR(got_y, want_y, 0.08 * want_y) << e;
  }
}

TEST_F(GpuTest, BlurLeavesTheFoveaAndNearPeripheryUntouchedAtTheModelsScale) {
  // With MAR₀ = 1′ σ stays below 0.5 px out to ~30° on this raster: those pixels pass unchanged.
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(320, 360);
  reconstruct::ReconSettings s;
  s.denoiser = reconstruct::Denoiser::None;
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), {}, s, {}, true);
  p.render(core::eye_poses(scene.camera, display.ipd_m), {glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)}, 0);
  const core::View v = p.view(core::Eye::Left);
  core::Image img(v.width(), v.height());
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) img.at(x, y) = glm::vec4(float((x * 7 + y * 13) % 5), 0, 0, 1);  // pixel-scale detail
  const core::Image out = pipeline::testing::blur_image(p, core::Eye::Left, img);
  int changed_inside = 0, inside = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const double e = core::angle_deg(v.pixel_to_dir({x + 0.5, y + 0.5}), glm::dvec3(0, 0, -1));
      if (e > 20) continue;
      ++inside;
      changed_inside += out.at(x, y).x != img.at(x, y).x ? 1 : 0;
    }
  EXPECT_GT(inside, 1000);
  EXPECT_EQ(changed_inside, 0);
}
