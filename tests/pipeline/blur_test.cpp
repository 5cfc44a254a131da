// The peripheral blur follows the acuity model: σ(e) = √(ln 2 / 2) / π · MAR₀ / m(e)
// (reconstruct::blur_sigma_deg). The kernel's width is measured on the GPU from the blurred
// image of a single bright pixel (its second moment along each axis; the display-space pass,
// which Cartesian and the screen-polar grids use) or of a single bright cell of an angular
// Visual-Polar grid (the grid-space pass: second moments in degrees across and along the
// rings), and compared with the formula converted by the raster's local pixel size or read
// in degrees directly.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

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

namespace {
core::DistributionParams cartesian() {
  core::DistributionParams dp;
  dp.kind = core::DistributionKind::Cartesian;
  return dp;
}

// One frame of the Cornell box, gaze at the view centre, on a width×height raster with the
// blur's MAR₀ = mar_deg: the mapping the blur kernels read.
struct BlurRig {
  BlurRig(fovea::gpu::Context& ctx, int width, int height, double mar_deg, const core::DistributionParams& dp)
      : scene(renderer::load_scene("cornell")), gs(ctx, scene), display(fovea::test::display_of_size(width, height)) {
    settings.denoiser = reconstruct::Denoiser::None;
    settings.blur_mar_fovea_deg = mar_deg;
    p = std::make_unique<pipeline::FramePipeline>(ctx, gs, core::stereo_views(display), dp, settings,
                                                  renderer::PathConfig{}, true);
    p->render(core::eye_poses(scene.camera, display), {glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)}, 0);
  }
  renderer::Scene scene;
  renderer::GpuScene gs;
  core::DisplayPreset display;
  reconstruct::ReconSettings settings;
  std::unique_ptr<pipeline::FramePipeline> p;
};
}  // namespace

TEST_F(GpuTest, BlurWidthFollowsTheAcuityModelAcrossEccentricities) {
  // 16′ instead of 1′ scales every σ by 16, into whole pixels on this raster (1.7–13 px).
  BlurRig rig(ctx(), 640, 720, 16.0 / 60.0, cartesian());
  pipeline::FramePipeline& p = *rig.p;
  const reconstruct::ReconSettings& s = rig.settings;
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
  BlurRig rig(ctx(), 320, 360, reconstruct::kMarFoveaDeg, cartesian());
  pipeline::FramePipeline& p = *rig.p;
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

TEST_F(GpuTest, GridBlurWidthFollowsTheAcuityModelInDegrees) {
  BlurRig rig(ctx(), 640, 720, 16.0 / 60.0, {});  // σ of 1–4 cells on this grid at 20–45°
  pipeline::FramePipeline& p = *rig.p;
  const reconstruct::ReconSettings& s = rig.settings;
  const core::SampleDistribution& d = p.distribution(core::Eye::Left);
  const auto& table = d.column_table();
  const auto mid = [&](int c) { return 0.5 * (double(table[std::size_t(c)].r0) + double(table[std::size_t(c)].r1)); };
  // φ of row r's centre in column c (rg_row_to_t).
  const auto phi = [&](int c, int r) {
    const auto& col = table[std::size_t(c)];
    return double(col.phi0) + (r + 0.5) / col.rows * (2 * std::numbers::pi - double(col.phi_gap));
  };
  const int pcols = d.padded_columns();
  for (double e : {20.0, 30.0, 40.0, 45.0}) {
    int c0 = 0;
    for (int c = 0; c < d.columns(); ++c)
      if (std::abs(mid(c) - e) < std::abs(mid(c0) - e)) c0 = c;
    const int r0 = int(table[std::size_t(c0)].rows) / 2;
    std::vector<glm::vec4> grid(std::size_t(pcols) * d.padded_rows(), glm::vec4(0, 0, 0, 1));  // every cell sampled
    grid[std::size_t(r0) * pcols + c0] = glm::vec4(1, 0, 0, 1);
    const std::vector<glm::vec4> out = pipeline::testing::blur_grid(p, core::Eye::Left, grid);
    const double e0 = mid(c0), phi0 = phi(c0, r0);
    double sum = 0, m_rho = 0, m_phi = 0;
    for (int c = 0; c < d.columns(); ++c)
      for (int r = 0; r < int(table[std::size_t(c)].rows); ++r) {
        const double w = out[std::size_t(r) * pcols + c].x;
        if (w == 0) continue;
        double dphi = std::remainder(phi(c, r) - phi0, 2 * std::numbers::pi);
        const double along = dphi * std::sin(mid(c) * std::numbers::pi / 180) * 180 / std::numbers::pi;  // degrees on the ring
        sum += w, m_rho += w * (mid(c) - e0) * (mid(c) - e0), m_phi += w * along * along;
      }
    const double want = reconstruct::blur_sigma_deg(e0, s.blur_mar_fovea_deg);
    const double got_rho = std::sqrt(m_rho / sum), got_phi = std::sqrt(m_phi / sum);
    const auto& col = table[std::size_t(c0)];
    std::printf("e %.1f deg: cell %.3f x %.3f deg, sigma across %.3f deg, along %.3f deg (model %.3f)\n", e0,
                double(col.r1 - col.r0), 360 * std::sin(e0 * std::numbers::pi / 180) / col.rows, got_rho, got_phi, want);
    EXPECT_NEAR(sum, 1.0, 0.05) << e;  // renormalised gather: energy kept up to the kernel's variation
    EXPECT_NEAR(got_rho, want, 0.1 * want) << e;
    EXPECT_NEAR(got_phi, want, 0.1 * want) << e;
  }
}

TEST_F(GpuTest, GridBlurLeavesCellsWhoseKernelIsBelowHalfACellUntouched) {
  // At the model's scale (MAR₀ = 1′) σ is below half a cell on every column of this grid:
  // the grid-space pass must not change a cell (nor be recorded at all).
  BlurRig rig(ctx(), 320, 360, reconstruct::kMarFoveaDeg, {});
  const core::SampleDistribution& d = rig.p->distribution(core::Eye::Left);
  std::vector<glm::vec4> grid(std::size_t(d.padded_columns()) * d.padded_rows());
  for (std::size_t i = 0; i < grid.size(); ++i) grid[i] = glm::vec4(float((i * 7) % 5), 0, 0, 1);  // cell-scale detail
  EXPECT_EQ(pipeline::testing::blur_grid(*rig.p, core::Eye::Left, grid), grid);
  // With MAR₀ = 16′ the outer columns are blurred (the same pass is live).
  BlurRig wide(ctx(), 320, 360, 16.0 / 60.0, {});
  EXPECT_NE(pipeline::testing::blur_grid(*wide.p, core::Eye::Left, grid), grid);
}
