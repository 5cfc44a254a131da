#include "fovea/renderer/path_tracer.hpp"

#include <cmath>
#include <limits>


#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/shaders/live_cells.h"
#include "fovea/shaders/pt_bindings.h"
#include "fovea/shaders/pt_order.h"
#include "tracer_pipeline.hpp"

namespace fovea::renderer {

namespace {
// The scene data read per ray or path vertex are texel buffers (nodes, triangles, shading,
// materials, lights, texture texels, GGX albedo), the rest storage buffers.
std::vector<gpu::Binding> set0_bindings() {
  std::vector<gpu::Binding> b(PT_BINDING_COUNT, gpu::Binding::StorageBuffer);
  for (const int i : {PT_BINDING_NODES, PT_BINDING_TRIS, PT_BINDING_SHADING, PT_BINDING_MATERIALS, PT_BINDING_LIGHTS,
                      PT_BINDING_TEXELS, PT_BINDING_GGX_ALBEDO})
    b[std::size_t(i)] = gpu::Binding::TexelBuffer;
  return b;
}
}  // namespace

PathTracer::PathTracer(gpu::Context& ctx, const GpuScene& scene) : PathTracer(ctx, scene, scene.features()) {}

PathTracer::PathTracer(gpu::Context& ctx, const GpuScene& scene, const SceneFeatures& f) : ctx_(ctx), scene_(scene) {
  if (!f.covers(scene.features()))
    throw core::InputError("path tracer: the requested shader features lack some the scene uses");
  using gpu::SpecConstant;
  pipeline_ = gpu::ComputePipeline(
      ctx, tracer_pipeline(scene, "pt_trace", set0_bindings(),
                           sizeof(shaders::PtFrameParams),
                           {SpecConstant::boolean(shaders::kPtSpecTextures, f.textures),
                            SpecConstant::boolean(shaders::kPtSpecGlossy, f.glossy),
                            SpecConstant::boolean(shaders::kPtSpecEmitters, f.emitters)}));
  no_list_ = gpu::Buffer(ctx, {.size = shaders::kLiveHeaderWords * sizeof(std::uint32_t), .name = "pt.no_live_list"});
}

TraceOutputs PathTracer::bind(const gpu::Buffer& grid, GridExtent extent, const gpu::Buffer* live) const {
  if (extent.columns == 0 || extent.rows == 0 || std::uint64_t(extent.columns) * extent.rows > 0xFFFFFFFFu)
    throw core::InputError("path tracer: grid extent " + std::to_string(extent.columns) + "x" +
                           std::to_string(extent.rows) + " out of range");
  const VkDeviceSize tiles = VkDeviceSize(extent.columns) * extent.rows / shaders::kLiveTileCells;
  if (live && live->size() < (shaders::kLiveHeaderWords + tiles) * sizeof(std::uint32_t))
    throw core::InputError("path tracer: the live-tile list holds fewer entries than the grid's tiles");
  TraceOutputs o = bind(grid, extent.columns * extent.rows);
  o.extent_ = extent;
  if (live) {
    o.live_ = live;
    o.set_.bind(PT_BINDING_LIVE_LIST, *live);
  }
  return o;
}

TraceOutputs PathTracer::bind(const gpu::Buffer& grid, std::uint32_t cells) const {
  if (cells == 0) throw core::InputError("path tracer: empty sample grid");
  if (grid.size() < VkDeviceSize(cells) * sizeof(shaders::GridSample))
    throw core::InputError("path tracer: grid buffer holds fewer than " + std::to_string(cells) + " samples");
  TraceOutputs o;
  o.cells_ = cells;
  const VkDeviceSize bytes = VkDeviceSize(cells) * sizeof(glm::vec4);
  auto make = [&](const char* name) {  // also RGBA32F texels for the reconstruction's reads
    return gpu::Buffer(ctx_, {bytes, gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal, name,
                              VK_FORMAT_R32G32B32A32_SFLOAT});
  };
  o.direct_ = make("pt.out.direct");
  o.indirect_ = make("pt.out.indirect");
  o.albedo_ = make("pt.out.albedo");
  o.normal_depth_ = make("pt.out.normal_depth");
  o.position_material_ = make("pt.out.position_material");
  o.radiance_ = make("pt.out.radiance");
  o.set_ = gpu::DescriptorSet(ctx_, pipeline_.set_layout(0));
  o.set_.bind(PT_BINDING_NODES, scene_.nodes()).bind(PT_BINDING_TRIS, scene_.triangles());
  o.set_.bind(PT_BINDING_SHADING, scene_.shading()).bind(PT_BINDING_MATERIALS, scene_.materials());
  o.set_.bind(PT_BINDING_LIGHTS, scene_.lights()).bind(PT_BINDING_TEX_TABLE, scene_.texture_table());
  o.set_.bind(PT_BINDING_TEXELS, scene_.texels()).bind(PT_BINDING_GRID, grid);
  o.set_.bind(PT_BINDING_OUT_DIRECT, o.direct_).bind(PT_BINDING_OUT_INDIRECT, o.indirect_);
  o.set_.bind(PT_BINDING_OUT_ALBEDO, o.albedo_).bind(PT_BINDING_OUT_NORMAL_DEPTH, o.normal_depth_);
  o.set_.bind(PT_BINDING_OUT_POSITION_MATERIAL, o.position_material_).bind(PT_BINDING_OUT_RADIANCE, o.radiance_);
  o.set_.bind(PT_BINDING_GGX_ALBEDO, scene_.ggx_albedo()).bind(PT_BINDING_LIVE_LIST, no_list_);
  return o;
}

void PathTracer::record(VkCommandBuffer cmd, TraceOutputs& out, const core::View& view, core::Eye eye,
                        std::uint32_t frame, const PathConfig& c, std::uint32_t accumulated) const {
  shaders::PtFrameParams p{};
  set_eye_pose(p, view, "path tracer");
  const glm::vec3 env = scene_.environment();
  p.env_r = env.x; p.env_g = env.y; p.env_b = env.z;
  p.light_count = scene_.light_count();
  p.cell_count = out.cells_;
  p.frame = frame;
  p.eye = static_cast<std::uint32_t>(eye);
  p.max_bounces = c.max_bounces < 0 ? std::numeric_limits<std::uint32_t>::max() : std::uint32_t(c.max_bounces);
  p.rr_start = c.rr_start;
  p.pixel_tx = float((view.tan_right() - view.tan_left()) / view.width());
  p.pixel_ty = float((view.tan_up() - view.tan_down()) / view.height());
  p.columns = out.extent_.columns;
  const bool tiles = c.order == TraceOrder::Tiles, listed = c.order == TraceOrder::Live;
  if (listed && !out.live_)
    throw core::InputError("path tracer: live order needs the grid pass's live-tile list bound");
  if (tiles && (out.extent_.columns == 0 || out.extent_.columns % shaders::kPtTileColumns != 0 ||
                out.extent_.rows % shaders::kPtTileRows != 0))
    throw core::InputError("path tracer: tile order needs a grid of whole " + std::to_string(shaders::kPtTileColumns) +
                           "x" + std::to_string(shaders::kPtTileRows) + " tiles bound with its extent, not " +
                           std::to_string(out.extent_.columns) + "x" + std::to_string(out.extent_.rows) + " cells");
  const std::uint32_t spp = std::max<std::uint32_t>(c.spp, 1);
  std::uint64_t done = std::uint64_t(accumulated) * spp;
  for (std::uint32_t first = 0; first < spp; first += shaders::kPtMaxSppPerDispatch) {
    if (first) gpu::compute_to_compute(cmd);
    p.spp = std::min(spp - first, shaders::kPtMaxSppPerDispatch);
    p.sample_offset = first;
    p.accumulated_samples = std::uint32_t(std::min<std::uint64_t>(done, 0xFFFFFFFFu));
    const bool boost = first == 0 && done == 0 && spp == 1 && c.boost_spp > 1;
    p.boost_spp = boost ? std::min(c.boost_spp, shaders::kPtMaxSppPerDispatch) : 0u;
    p.boost_deg = float(c.boost_deg);
    p.flags = (c.jitter ? shaders::kPtJitter : 0u) | (done > 0 ? shaders::kPtAccumulate : 0u) |
              (tiles ? shaders::kPtTileOrder : 0u) | (listed ? shaders::kPtLiveList : 0u);
    p.texture_cone = float(std::max(c.texture_cone, 0.0));
    if (scene_.tracing() == Tracing::RayQuery) pipeline_.bind(cmd, {&out.set_, &scene_.ray_query_set()});
    else pipeline_.bind(cmd, {&out.set_});
    pipeline_.push(cmd, p);
    if (listed) pipeline_.dispatch_indirect(cmd, *out.live_, shaders::kLiveArgsLive * sizeof(std::uint32_t));
    else pipeline_.dispatch_linear(cmd, out.cells_);
    done += p.spp;
  }
}

PathConfig albedo_path_config(const AlbedoStats& a, PathConfig c) {
  // Least n >= 1 with x^n <= limit, at most `cap` (also for x close to 1).
  const auto least_power = [](double x, double limit, int cap) {
    if (!(x > limit)) return 1;
    if (x >= 0.999) return cap;
    return std::clamp(int(std::ceil(std::log(limit) / std::log(x) - 1e-9)), 1, cap);
  };
  c.max_bounces = a.max >= 0.999f ? -1 : least_power(a.max, kAlbedoBounceCutoff, int(shaders::kPtHardMaxBounces));
  c.rr_start = std::uint32_t(least_power(a.mean, kAlbedoRouletteStart, kAlbedoRouletteLatest));
  return c;
}

std::vector<shaders::GridSample> cartesian_grid(const core::View& view) {
  std::vector<shaders::GridSample> g(std::size_t(view.width()) * view.height());
  for (int y = 0; y < view.height(); ++y)
    for (int x = 0; x < view.width(); ++x) {
      const glm::dvec2 px(x + 0.5, y + 0.5);
      const glm::dvec3 d = view.pixel_to_dir(px);
      auto& s = g[std::size_t(y) * view.width() + x];
      s.dir_x = float(d.x);
      s.dir_y = float(d.y);
      s.dir_z = float(d.z);
      s.flags = 0;
      s.screen_x = float(px.x);
      s.screen_y = float(px.y);
      s.ecc_deg = float(core::angle_deg(d, view.centre_dir()));
      s.footprint = 1.0f;
    }
  return g;
}

}  // namespace fovea::renderer
