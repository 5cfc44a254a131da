// Textures are kept whatever lights them (docs/reconstruction.md, "Albedo demodulation"):
// direct and indirect light are divided by the primary hit's albedo before accumulation,
// stereo sharing and BMFR, and multiplied back after, so a textured wall lit only by light
// bounced off a white panel keeps its texture as well as the same wall lit directly. Fovea
// SSIM against a converged reference of the same light transport, after 16 still frames
// (measured: directly 0.995, only indirectly 0.986). The indirectly lit wall's reference
// needs ~4096 spp: at 1024 its own noise held its SSIM near 0.91.
#include <cstdio>
#include <vector>

#include "fovea/core/metrics.hpp"
#include "fovea/renderer/reference.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace texture_demod {

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

constexpr int kWidth = 128, kHeight = 144;  // the tiny preset's optics at this raster
const std::array<glm::dvec3, 2> kGaze{glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)};

// A 16×16 checkerboard of albedo 0.15 / 0.85 (sRGB bytes) on the back wall of a white room
// (x, y in [−2, 2], z in [−2, 3]; double-sided Lambert walls), seen from the origin looking
// down −Z. A small light at z = 1 behind the viewer faces the textured wall (`direct`), or
// faces away from it, so that the wall sees only what the other walls reflect (the light's
// back face is black and opaque).
renderer::Scene checker_room(bool direct) {
  renderer::Scene s;
  s.name = direct ? "checker-direct" : "checker-indirect";
  s.textures.push_back(fovea::test::grey_texture("checker", 16, 16, [](int x, int y) {
    return std::uint8_t((x + y) % 2 ? 237 : 108);  // sRGB of linear 0.85 and 0.15
  }));
  const renderer::Material wall = fovea::test::textured_material(0);
  renderer::Material white = wall;
  white.base_color = glm::vec3(0.8f);
  white.base_color_texture = -1;
  renderer::Material light;
  light.base_color = glm::vec3(0.0f);
  light.specular = 0.0f;
  light.emission = glm::vec3(direct ? 10.0f : 80.0f);  // about the same brightness on the wall
  light.double_sided = false;
  const std::uint32_t mw = s.add_material(wall), mp = s.add_material(white), ml = s.add_material(light);
  s.add_quad({-2, -2, -2}, {2, -2, -2}, {2, 2, -2}, {-2, 2, -2}, mw);  // the textured wall
  s.add_quad({-2, -2, 3}, {2, -2, 3}, {2, 2, 3}, {-2, 2, 3}, mp);
  s.add_quad({-2, -2, -2}, {2, -2, -2}, {2, -2, 3}, {-2, -2, 3}, mp);
  s.add_quad({-2, 2, -2}, {2, 2, -2}, {2, 2, 3}, {-2, 2, 3}, mp);
  s.add_quad({-2, -2, -2}, {-2, 2, -2}, {-2, 2, 3}, {-2, -2, 3}, mp);
  s.add_quad({2, -2, -2}, {2, 2, -2}, {2, 2, 3}, {2, -2, 3}, mp);
  const float h = 0.5f;
  if (direct)
    s.add_quad({-h, -h, 1}, {-h, h, 1}, {h, h, 1}, {h, -h, 1}, ml);  // faces −Z: the textured wall
  else
    s.add_quad({-h, -h, 1}, {h, -h, 1}, {h, h, 1}, {-h, h, 1}, ml);  // faces +Z: away from it
  return s;
}

struct Fovea {
  double ssim = 0, mean = 0;  // fovea SSIM, and the reference's mean luminance there
};

Fovea fovea_ssim(fovea::gpu::Context& ctx, const renderer::Scene& scene) {
  renderer::GpuScene gs(ctx, scene, {}, fovea::test::kStatisticsTracing);
  const core::DisplayPreset display = fovea::test::display_of_size(kWidth, kHeight);
  pipeline::FramePipeline p(ctx, gs, core::stereo_views(display), {}, reconstruct::ReconSettings{}, {}, /*mono=*/true);
  const auto poses = core::eye_poses(scene.camera, display);
  for (std::uint32_t f = 0; f < 16; ++f) p.render(poses, kGaze, f);
  renderer::ReferenceOptions o;  // the pipeline's transport: PathConfig{}
  o.path.spp = 64;
  o.max_spp = 4096;
  o.until_pixel_rel_error = 0.01;  // the indirectly lit wall needs ~4096, the lit one far fewer
  const fovea::test::FoveaReference ref = fovea::test::fovea_reference(ctx, gs, p.view(core::Eye::Left), kGaze[0], o);
  double lum = 0, n = 0;
  for (std::size_t i = 0; i < ref.weights.size(); ++i) {
    const glm::vec4 c = ref.image.pixels[i];
    lum += ref.weights[i] * (0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z);
    n += ref.weights[i];
  }
  return {fovea::test::fovea_scores(p.image(core::Eye::Left), ref).ssim, lum / n};
}

TEST_F(GpuTest, TextureLitOnlyIndirectlyKeepsItsDetail) {
  const Fovea direct = fovea_ssim(ctx(), checker_room(true));
  const Fovea indirect = fovea_ssim(ctx(), checker_room(false));
  std::printf("fovea SSIM: lit directly %.4f (mean luminance %.3f), only indirectly %.4f (%.3f)\n", direct.ssim,
              direct.mean, indirect.ssim, indirect.mean);
  // Both walls are lit (a light facing the wrong way would leave one black and trivially sharp).
  EXPECT_GT(direct.mean, 0.05);
  EXPECT_GT(indirect.mean, 0.05);
  EXPECT_GT(direct.ssim, 0.5);
  EXPECT_NEAR(indirect.ssim, direct.ssim, 0.05);
}

}  // namespace texture_demod
