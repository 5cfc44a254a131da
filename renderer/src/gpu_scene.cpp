#include "fovea/renderer/gpu_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/geometric.hpp>

#include "fovea/core/clock.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"
#include "fovea/gpu/accel.hpp"
#include "ggx_albedo.hpp"
#include "tracer_pipeline.hpp"

namespace fovea::renderer {

namespace {

template <class T>
gpu::Buffer upload(gpu::Context& ctx, const std::vector<T>& data, const char* name,
                   VkFormat texel_format = VK_FORMAT_UNDEFINED) {
  gpu::Buffer b(ctx, {data.size() * sizeof(T), gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal, name, texel_format});
  b.upload(data);
  return b;
}

// Appends texture t and its box-filtered mip chain to `texels` (level l of max(w >> l, 1) ×
// max(h >> l, 1) texels right after level l − 1; a texel of level l + 1 averages the 2×2
// texels below it, in linear light for the colour); returns the number of levels. The
// tracer picks a level from the primary ray's cone (pt_trace.comp, cone_lod).
std::uint32_t append_mip_chain(const Texture& t, std::vector<std::uint32_t>& texels) {
  std::vector<glm::vec4> level(std::size_t(t.width) * t.height);
  for (std::size_t i = 0; i < level.size(); ++i)
    level[i] = {core::srgb_decode(t.rgba[4 * i] / 255.0f), core::srgb_decode(t.rgba[4 * i + 1] / 255.0f),
                core::srgb_decode(t.rgba[4 * i + 2] / 255.0f), t.rgba[4 * i + 3] / 255.0f};
  auto byte = [](float v) { return std::uint32_t(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  int w = t.width, h = t.height;
  std::uint32_t levels = 0;
  // Level 0 as loaded (RGBA8 bytes in unpackUnorm4x8 order); the others encoded from linear.
  const std::size_t first = texels.size();
  texels.resize(first + level.size());
  std::memcpy(texels.data() + first, t.rgba.data(), t.rgba.size());
  for (;;) {
    if (levels > 0)
      for (const glm::vec4& c : level)
        texels.push_back(byte(core::srgb_encode(c.x)) | byte(core::srgb_encode(c.y)) << 8 |
                         byte(core::srgb_encode(c.z)) << 16 | byte(c.w) << 24);
    ++levels;
    if (w == 1 && h == 1) return levels;
    const int nw = std::max(w / 2, 1), nh = std::max(h / 2, 1);
    std::vector<glm::vec4> next(std::size_t(nw) * nh);
    for (int y = 0; y < nh; ++y)
      for (int x = 0; x < nw; ++x) {
        const int x0 = std::min(2 * x, w - 1), x1 = std::min(2 * x + 1, w - 1);
        const int y0 = std::min(2 * y, h - 1), y1 = std::min(2 * y + 1, h - 1);
        next[std::size_t(y) * nw + x] = 0.25f * (level[std::size_t(y0) * w + x0] + level[std::size_t(y0) * w + x1] +
                                                 level[std::size_t(y1) * w + x0] + level[std::size_t(y1) * w + x1]);
      }
    level = std::move(next);
    w = nw;
    h = nh;
  }
}

}  // namespace

Tracing parse_tracing(std::string_view s, std::string_view what) {
  for (Tracing t : {Tracing::Auto, Tracing::RayQuery, Tracing::Compute})
    if (s == tracing_name(t)) return t;
  throw core::InputError(std::string(what) + ": expected auto, rayquery or compute, got \"" + std::string(s) + "\"");
}

const char* tracing_name(Tracing t) {
  switch (t) {
    case Tracing::Auto: return "auto";
    case Tracing::RayQuery: return "rayquery";
    case Tracing::Compute: return "compute";
  }
  return "?";
}

gpu::ComputePipelineDesc tracer_pipeline(const GpuScene& scene, const char* shader, std::vector<gpu::Binding> set0,
                                         std::uint32_t push_constant_bytes,
                                         std::vector<gpu::SpecConstant> specialization) {
  const bool rq = scene.tracing() == Tracing::RayQuery;
  specialization.push_back(gpu::SpecConstant::u32(shaders::kPtSpecBvhStack, scene.bvh_stack()));
  specialization.push_back(gpu::SpecConstant::u32(shaders::kPtSpecSharedBytes, scene.shared_memory_bytes()));
  gpu::ComputePipelineDesc d{std::string(shader) + (rq ? ".rayquery.comp.spv" : ".comp.spv"), {std::move(set0)},
                             push_constant_bytes, std::move(specialization)};
  if (rq) d.sets.push_back({gpu::Binding::AccelerationStructure});
  return d;
}

GpuScene::~GpuScene() = default;

GpuScene::GpuScene(gpu::Context& ctx, const Scene& s, const BvhOptions& bvh_options, Tracing tracing) {
  using namespace shaders;
  if (tracing == Tracing::RayQuery && !ctx.features().ray_query)
    throw core::InputError("--trace rayquery: the Vulkan device '" + ctx.info().name + "' (" + ctx.info().driver +
                           ") does not offer ray queries (VK_KHR_acceleration_structure + VK_KHR_ray_query); "
                           "use --trace compute or auto");
  const core::TimeNs t0 = core::now_ns();
  // The compute traversal gets the tree built for the rays from the scene camera; with ray
  // queries the nodes go unused (and the triangle order stays the SAH tree's).
  const bool ray_queries = tracing != Tracing::Compute && ctx.features().ray_query;
  BvhOptions options = bvh_options;
  if (!options.eye && !ray_queries) options.eye = glm::vec3(s.camera.position);
  const Bvh bvh = build_bvh(s.positions, options);
  stats_.build_ms = core::ns_to_ms(core::now_ns() - t0);
  const std::size_t n = bvh.order.size();

  // Lights: emissive triangles, chosen with probability proportional to their power.
  std::vector<std::uint32_t> slot_of(n);
  for (std::size_t i = 0; i < n; ++i) slot_of[bvh.order[i]] = std::uint32_t(i);
  std::vector<PtLight> lights;
  double total = 0;
  for (std::size_t t = 0; t < n; ++t) total += triangle_power(s, t);
  std::vector<float> light_pdf(n, 0.0f);
  if (total > 0) {
    double acc = 0;
    for (std::size_t t = 0; t < n; ++t) {
      const float p = triangle_power(s, t);
      if (!(p > 0)) continue;
      const glm::vec3* v = &s.positions[3 * t];
      const float area = 0.5f * glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
      acc += p;
      const float pmf = float(p / total);
      lights.push_back({slot_of[t], float(acc / total), pmf, area});
      light_pdf[t] = pmf / area;
    }
    lights.back().cdf = 1.0f;  // no rounding gap at the top of the CDF
  }
  stats_.lights = std::uint32_t(lights.size());
  if (lights.empty()) lights.push_back({0, 1.0f, 0.0f, 0.0f});

  std::vector<PtTriangle> tris(n);
  std::vector<PtShading> shading(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t t = bvh.order[i];
    const glm::vec3* p = &s.positions[3 * t];
    const glm::vec3* nn = &s.normals[3 * t];
    const glm::vec2* uv = &s.uvs[3 * t];
    tris[i] = {p[0].x, p[0].y, p[0].z, s.material[t], p[1].x, p[1].y, p[1].z, t, p[2].x, p[2].y, p[2].z, light_pdf[t]};
    shading[i] = {nn[0].x, nn[0].y, nn[0].z, nn[1].x, nn[1].y, nn[1].z, nn[2].x, nn[2].y, nn[2].z,
                  uv[0].x, uv[0].y, uv[1].x, uv[1].y, uv[2].x, uv[2].y, 0.0f};
  }

  features_ = {false, false, false};
  for (const Material& m : s.materials) {
    features_.textures |= m.base_color_texture >= 0;
    features_.glossy |= m.specular != 0.0f || m.metallic != 0.0f;
    features_.emitters |= m.emission != glm::vec3(0.0f);
  }
  std::vector<PtMaterial> mats;
  for (const Material& m : s.materials)
    mats.push_back({m.base_color.x, m.base_color.y, m.base_color.z, m.base_color_texture, m.emission.x, m.emission.y,
                    m.emission.z, m.metallic, m.roughness, m.specular, m.double_sided ? 1u : 0u, 0.0f});

  std::vector<PtTextureInfo> table;
  std::vector<std::uint32_t> texels;
  for (const Texture& t : s.textures) {
    const std::uint32_t offset = std::uint32_t(texels.size());
    table.push_back({offset, std::uint32_t(t.width), std::uint32_t(t.height), append_mip_chain(t, texels)});
  }
  stats_.textures = std::uint32_t(table.size());
  if (table.empty()) table.push_back({0, 1, 1, 1});
  if (texels.empty()) texels.push_back(0xFFFFFFFFu);

  // Also texel buffers, the tracers' reads (pt_traverse.h says why).
  nodes_ = upload(ctx, bvh.nodes, "pt.bvh_nodes", VK_FORMAT_R32G32B32A32_UINT);
  triangles_ = upload(ctx, tris, "pt.triangles", VK_FORMAT_R32G32B32A32_UINT);
  shading_ = upload(ctx, shading, "pt.shading", VK_FORMAT_R32G32B32A32_SFLOAT);
  materials_ = upload(ctx, mats, "pt.materials", VK_FORMAT_R32G32B32A32_SFLOAT);
  lights_ = upload(ctx, lights, "pt.lights", VK_FORMAT_R32G32B32A32_SFLOAT);
  texture_table_ = upload(ctx, table, "pt.texture_table");
  texels_ = upload(ctx, texels, "pt.texels", VK_FORMAT_R32_UINT);
  ggx_albedo_ = upload(ctx, ggx_albedo_table(), "pt.ggx_albedo", VK_FORMAT_R32G32B32A32_SFLOAT);
  environment_ = s.environment;
  stats_.triangles = std::uint32_t(n);
  stats_.nodes = std::uint32_t(bvh.nodes.size());
  stats_.bvh_depth = bvh.depth;
  shared_memory_bytes_ = ctx.info().max_shared_memory_bytes;
  stats_.bvh_sah_cost = bvh.sah_cost;
  stats_.bvh_ray_guided = bvh.ray_guided;
  stats_.bvh_ray_cost = bvh.ray_cost;
  stats_.bvh_sah_ray_cost = bvh.sah_ray_cost;

  if (ray_queries) {
    // The triangles in BVH order, so a ray query's primitive index addresses tris[] as
    // the compute traversal's hits do.
    std::vector<float> vertices;
    vertices.reserve(9 * n);
    for (const PtTriangle& t : tris)
      vertices.insert(vertices.end(), {t.v0_x, t.v0_y, t.v0_z, t.v1_x, t.v1_y, t.v1_z, t.v2_x, t.v2_y, t.v2_z});
    const core::TimeNs t1 = core::now_ns();
    accel_ = std::make_unique<gpu::TriangleAccel>(ctx, vertices);
    stats_.accel_build_ms = core::ns_to_ms(core::now_ns() - t1);
    stats_.accel_bytes = accel_->bytes();
    accel_layout_ = gpu::DescriptorSetLayout(ctx, {gpu::Binding::AccelerationStructure});
    accel_set_ = gpu::DescriptorSet(ctx, accel_layout_);
    accel_set_.bind(PT_BINDING_TLAS, *accel_);
  }
}

}  // namespace fovea::renderer
