// A fine texture at a grazing angle near the gaze, at 16 pixels per degree (the `modern`
// preset's), with the gaze still and drifting as a fixating eye's does: bricks on a floor
// met at 8°, whose mortar lines are a pixel or two wide. Fovea SSIM and HDR-FLIP of the last
// of 16 frames against a converged reference of the same light transport (the fovea only, a
// reference window), Visual-Polar at the default budget and full-resolution Cartesian, on
// the same scene, gaze and frames (docs/reconstruction.md, "Textures under sparse cells").
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "fovea/core/metrics.hpp"
#include "fovea/renderer/reference.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace grazing_texture {

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

constexpr int kSize = 512;     // ±16° at 512 pixels: 16 pixels per degree at the centre
constexpr int kFrames = 16;

// A floor of bricks (64×32-texel bricks, 8-texel dark mortar) at y = −1 under a constant
// sky, seen from the origin: at 8° below the horizon the floor is 7 m away and met at 8°.
renderer::Scene brick_floor() {
  renderer::Scene s;
  s.name = "brick-floor";
  constexpr int kTex = 256;
  renderer::Texture t{"bricks", kTex, kTex, {}};
  for (int y = 0; y < kTex; ++y)
    for (int x = 0; x < kTex; ++x) {
      const int course = y / 32, xs = x + (course % 2) * 32;  // every other course shifted half a brick
      const bool mortar = y % 32 < 8 || xs % 64 < 8;
      const std::uint8_t v = mortar ? 40 : 200;
      t.rgba.insert(t.rgba.end(), {v, std::uint8_t(v * 0.6), std::uint8_t(v * 0.4), 255});
    }
  s.textures.push_back(t);
  renderer::Material floor;
  floor.base_color = glm::vec3(1.0f);
  floor.base_color_texture = 0;
  floor.specular = 0.0f;
  floor.double_sided = true;
  const std::uint32_t m = s.add_material(floor);
  // uv 0..20 across 40 m: a 256-texel tile per 2 m, a brick 50 cm long and 25 cm deep.
  s.add_quad({-20, -1, 5}, {20, -1, 5}, {20, -1, -35}, {-20, -1, -35}, m);
  for (std::size_t i = s.uvs.size() - 6; i < s.uvs.size(); ++i) s.uvs[i] *= 20.0f;
  s.environment = glm::vec3(1.0f);
  return s;
}

core::DisplayPreset narrow_display() {
  core::DisplayPreset d = fovea::test::display_of_size(kSize, kSize);
  d.fov_left = d.fov_right = core::Fov::from_degrees(-16, 16, 16, -16);
  return d;
}

// 8° below the horizon, drifting by up to 0.3° (a fixating eye's drift and tremor).
glm::dvec3 gaze_at(std::uint32_t frame) {
  constexpr double kDeg = std::numbers::pi / 180;
  const double yaw = 0.3 * std::sin(0.7 * frame) * kDeg, pitch = (-8.0 + 0.3 * std::cos(1.1 * frame)) * kDeg;
  return {std::sin(yaw) * std::cos(pitch), std::sin(pitch), -std::cos(yaw) * std::cos(pitch)};
}

struct Scores {
  double ssim, hdr_flip;
};

class GrazingTexture : public GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    scene_ = brick_floor();
    gs_ = std::make_unique<renderer::GpuScene>(ctx(), scene_, renderer::BvhOptions{}, fovea::test::kStatisticsTracing);
    const core::View view = narrow_display().view(core::Eye::Left);
    renderer::ReferenceOptions o;  // the pipeline's transport: PathConfig{}
    o.path.spp = 32;
    o.max_spp = 256;
    reference_ = fovea::test::fovea_reference(ctx(), *gs_, view, gaze_at(kFrames - 1), o);
  }

  // The last frame's fovea; `still`: every frame at the last frame's gaze.
  Scores fovea(core::DistributionKind kind, bool still, bool pixel_albedo = true) {
    core::DistributionParams d;
    d.kind = kind;
    if (kind == core::DistributionKind::Cartesian) d.budget = 1.0;
    reconstruct::ReconSettings settings;
    settings.pixel_albedo = pixel_albedo;
    pipeline::FramePipeline p(ctx(), *gs_, core::stereo_views(narrow_display()), d, settings, {}, /*mono=*/true);
    const std::array<core::Pose, 2> poses{};
    for (std::uint32_t f = 0; f < kFrames; ++f) {
      const glm::dvec3 g = still ? gaze_at(kFrames - 1) : gaze_at(f);
      p.render(poses, {g, g}, f);
    }
    const core::Scores s = fovea::test::fovea_scores(p.image(core::Eye::Left), reference_);
    return {s.ssim, s.hdr_flip};
  }

  renderer::Scene scene_;
  std::unique_ptr<renderer::GpuScene> gs_;
  fovea::test::FoveaReference reference_;
};

TEST_F(GrazingTexture, BricksKeptWithoutMoire) {
  const Scores vp_still = fovea(core::DistributionKind::VisualPolar, true);
  const Scores cart_still = fovea(core::DistributionKind::Cartesian, true);
  const Scores vp_drift = fovea(core::DistributionKind::VisualPolar, false);
  const Scores cart_drift = fovea(core::DistributionKind::Cartesian, false);
  const Scores vp_cells = fovea(core::DistributionKind::VisualPolar, true, /*pixel_albedo=*/false);
  std::printf("fovea SSIM / HDR-FLIP at 16 ppd, grazing bricks: still gaze: visual-polar %.4f / %.4f (its cells' "
              "albedo alone %.4f / %.4f), cartesian %.4f / %.4f; drifting gaze: visual-polar %.4f / %.4f, cartesian "
              "%.4f / %.4f\n",
              vp_still.ssim, vp_still.hdr_flip, vp_cells.ssim, vp_cells.hdr_flip, cart_still.ssim, cart_still.hdr_flip,
              vp_drift.ssim, vp_drift.hdr_flip, cart_drift.ssim, cart_drift.hdr_flip);
  // Textures re-modulated from one sample per frame aliased (Cartesian 0.77, visual-polar
  // 0.66 with moiré fanning out from the gaze); the accumulated albedo is the box filter.
  // A texture cone of the whole cell on top of the jittered frames' box filter blurred them
  // (Cartesian 0.968, visual-polar 0.847; half a cell: 0.987 and 0.874).
  EXPECT_GT(cart_still.ssim, 0.98);
  EXPECT_GT(cart_drift.ssim, 0.98);  // the raster does not move with the gaze
  // Re-modulated with their cells' albedo, the polar cells' box filter and the resolve's tent
  // between cells blur the bricks into radial streaks (0.874); with each display pixel's own
  // first hits near the gaze (ReconSettings::pixel_albedo), 0.972 (docs/reconstruction.md,
  // "Textures at the display's resolution").
  EXPECT_GT(vp_cells.ssim, 0.86);
  EXPECT_GT(vp_still.ssim, 0.96);
  EXPECT_LT(vp_still.hdr_flip, vp_cells.hdr_flip - 0.08);
  // A drift within the grid's hold (0.5°) leaves the polar grid where it is, so the cells keep
  // their history as under a still gaze (moving the grid every frame: 0.74 against 0.83).
  EXPECT_GT(vp_drift.ssim, vp_still.ssim - 0.02);
}

}  // namespace grazing_texture
