#pragma once
// Test helpers: trace a grid with the path tracer and read the outputs back.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec4.hpp>

#include "fovea/gpu/barriers.hpp"
#include "fovea/renderer/path_tracer.hpp"

namespace fovea::test {

// The traversal of the image-statistics tests (tests/image-statistics-tests.txt). What they
// measure (sample statistics, reconstruction, denoising, energy) does not depend on how a hit
// is found, and both traversals find the same hits (RayQuery.*). The compute BVH is the one
// `--trace auto` takes on lavapipe, where it traces at twice the ray queries' rate. The other
// GPU tests (but the few that share these tests' fixtures) keep GpuScene's default, ray
// queries where the device has them.
inline constexpr renderer::Tracing kStatisticsTracing = renderer::Tracing::Compute;

// A grey texture of w × h texels, texel (x, y) = value(x, y) (sRGB-encoded), and a material
// that shows it: white base, no specular.
template <class Value>
renderer::Texture grey_texture(std::string name, int w, int h, Value value) {
  renderer::Texture t{std::move(name), w, h, {}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::uint8_t v = value(x, y);
      t.rgba.insert(t.rgba.end(), {v, v, v, 255});
    }
  return t;
}
inline renderer::Material textured_material(int texture) {
  renderer::Material m;
  m.base_color = glm::vec3(1.0f);
  m.base_color_texture = texture;
  m.specular = 0.0f;
  return m;
}

struct Traced {
  std::vector<glm::vec4> radiance, direct, indirect, albedo, normal_depth, position_material;
};

// `frames` frames of config.spp samples each, averaged on the GPU in one submission. The grid
// is bound with `extent` when given (columns > 0; needed by the tile order), else by its size.
inline Traced trace_grid(gpu::Context& ctx, const renderer::GpuScene& scene,
                         const std::vector<shaders::GridSample>& grid, const core::View& view, core::Eye eye,
                         const renderer::PathConfig& config, std::uint32_t frames = 1, std::uint32_t first_frame = 0,
                         renderer::GridExtent extent = {}) {
  gpu::Buffer g(ctx, {grid.size() * sizeof(shaders::GridSample), gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal,
                      "test.grid"});
  g.upload(grid);
  renderer::PathTracer pt(ctx, scene);
  renderer::TraceOutputs out = extent.columns > 0 ? pt.bind(g, extent) : pt.bind(g, std::uint32_t(grid.size()));
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    for (std::uint32_t f = 0; f < frames; ++f) {
      if (f) gpu::compute_to_compute(cmd);
      pt.record(cmd, out, view, eye, first_frame + f, config, f);
    }
  });
  Traced t;
  t.radiance = out.radiance().download<glm::vec4>();
  t.direct = out.direct().download<glm::vec4>();
  t.indirect = out.indirect().download<glm::vec4>();
  t.albedo = out.albedo().download<glm::vec4>();
  t.normal_depth = out.normal_depth().download<glm::vec4>();
  t.position_material = out.position_material().download<glm::vec4>();
  return t;
}

// Mean of per-cell estimates and the standard error of that mean (cells as independent
// samples; an upper bound where the cells' expected values differ).
struct MeanSe {
  double mean = 0, se = 0;
};
inline MeanSe mean_se(const std::vector<double>& v) {
  double s = 0, s2 = 0;
  for (double x : v) s += x, s2 += x * x;
  const double n = double(v.size()), m = s / n;
  return {m, n > 1 ? std::sqrt(std::max(0.0, s2 / n - m * m) / (n - 1)) : 0.0};
}

inline glm::dvec3 mean_rgb(const std::vector<glm::vec4>& v) {
  glm::dvec3 s(0);
  for (const auto& p : v) s += glm::dvec3(p);
  return s / double(v.size());
}

}  // namespace fovea::test
