// Scene-feature shader variants of the path tracer: each shipped scene gets the variant
// of what it uses, and its outputs equal the full shader's (same seeds) on every buffer.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/renderer/path_tracer.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"

namespace fr = fovea::renderer;
namespace fc = fovea::core;

namespace {

struct Case {
  const char* scene;
  fr::SceneFeatures expected;  // what the scene uses: the variant leaves the rest out
};

const Case kCases[] = {
    {"cornell", {false, false, true}},
    {"furnace", {false, false, true}},
    {"glossy-spheres", {false, true, true}},
    {"stereo-occluders", {true, false, true}},
    {"default", {true, true, true}},
};

std::vector<std::vector<glm::vec4>> render(fovea::gpu::Context& ctx, const fr::PathTracer& pt, const fc::View& view,
                                           const fovea::gpu::Buffer& grid, std::uint32_t cells) {
  fr::TraceOutputs out = pt.bind(grid, cells);
  fr::PathConfig config;
  config.spp = 2;
  config.max_bounces = 3;
  config.rr_start = 1;  // Russian roulette draws too
  config.jitter = true;
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    pt.record(cmd, out, view, fc::Eye::Left, 3, config);
    fovea::gpu::compute_to_compute(cmd);
    pt.record(cmd, out, view, fc::Eye::Left, 4, config, 1);
  });
  return {out.radiance().download<glm::vec4>(),     out.direct().download<glm::vec4>(),
          out.indirect().download<glm::vec4>(),     out.albedo().download<glm::vec4>(),
          out.normal_depth().download<glm::vec4>(), out.position_material().download<glm::vec4>()};
}

}  // namespace

class ShaderVariant : public fovea::test::GpuTest {};

TEST_F(ShaderVariant, EachSceneVariantEqualsTheFullShader) {
  const char* const names[] = {"radiance", "direct", "indirect", "albedo", "normal_depth", "position_material"};
  for (const Case& c : kCases) {
    SCOPED_TRACE(c.scene);
    const fr::Scene s = fr::load_scene(c.scene);
    fr::GpuScene g(ctx(), s);
    ASSERT_EQ(g.features(), c.expected);
    const fc::View view = fc::load_display("tiny").view(fc::Eye::Left, s.camera);
    const auto cells = fr::cartesian_grid(view);
    fovea::gpu::Buffer grid(ctx(), {cells.size() * sizeof(fovea::shaders::GridSample), fovea::gpu::BufferUsage::Storage,
                                    fovea::gpu::Memory::DeviceLocal, "test.grid"});
    grid.upload(cells);
    const auto variant = render(ctx(), fr::PathTracer(ctx(), g), view, grid, std::uint32_t(cells.size()));
    const auto full = render(ctx(), fr::PathTracer(ctx(), g, fr::SceneFeatures{}), view, grid, std::uint32_t(cells.size()));
    double sum = 0;
    for (std::size_t b = 0; b < full.size(); ++b) {
      // The variant only drops code that adds zero or multiplies by one for this scene;
      // the compiler may still round differently once it is gone.
      std::size_t exact = 0;
      for (std::size_t i = 0; i < full[b].size(); ++i)
        for (int k = 0; k < 4; ++k) {
          const float a = variant[b][i][k], f = full[b][i][k];
          ASSERT_NEAR(a, f, 1e-5f * (1.0f + std::abs(f))) << names[b] << " cell " << i;
          exact += a == f;
          sum += std::abs(f);
        }
      EXPECT_GT(double(exact), 0.99 * 4.0 * double(full[b].size())) << names[b];
    }
    EXPECT_GT(sum, 0.0) << "nothing rendered";
  }
}

TEST_F(ShaderVariant, FeaturesLackingWhatTheSceneUsesAreRefused) {
  const fr::Scene s = fr::load_scene("default");
  fr::GpuScene g(ctx(), s);
  EXPECT_THROW(fr::PathTracer(ctx(), g, fr::SceneFeatures{false, true, true}), fc::InputError);
  EXPECT_THROW(fr::PathTracer(ctx(), g, fr::SceneFeatures{true, false, true}), fc::InputError);
  EXPECT_THROW(fr::PathTracer(ctx(), g, fr::SceneFeatures{true, true, false}), fc::InputError);
  EXPECT_NO_THROW(fr::PathTracer(ctx(), g, fr::SceneFeatures{}));
}
