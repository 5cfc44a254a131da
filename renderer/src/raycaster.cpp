#include "fovea/renderer/raycaster.hpp"

#include <stdexcept>

#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/timer.hpp"
#include "tracer_pipeline.hpp"

namespace fovea::renderer {

namespace {

const GpuScene& checked(const GpuScene& scene, bool count_traversal) {
  if (count_traversal && scene.tracing() != Tracing::Compute)
    throw std::invalid_argument("Raycaster: traversal counters need the compute traversal, not ray queries");
  return scene;
}

}  // namespace

Raycaster::Raycaster(gpu::Context& ctx, const GpuScene& scene, bool count_traversal)
    : ctx_(ctx),
      scene_(checked(scene, count_traversal)),
      count_traversal_(count_traversal),
      pipeline_(ctx, tracer_pipeline(scene, count_traversal ? "pt_raycast.stats" : "pt_raycast",
                                     {gpu::Binding::TexelBuffer, gpu::Binding::TexelBuffer, gpu::Binding::StorageBuffer,
                                      gpu::Binding::StorageBuffer},
                                     sizeof(shaders::PtRaycastParams))) {}

TraversalStats Raycaster::traversal_stats() {
  if (!count_traversal_) throw std::logic_error("Raycaster::traversal_stats needs count_traversal");
  TraversalStats s;
  for (const shaders::PtHitRecord& h : trace(RayQuery::Closest)) {
    s.nodes += h.t;
    s.triangles += h.triangle;
    s.subgroup_nodes += h.u;
    s.subgroup_triangles += h.v;
  }
  const double n = double(count_);
  return {s.nodes / n, s.triangles / n, s.subgroup_nodes / n, s.subgroup_triangles / n};
}

void Raycaster::set_rays(std::span<const shaders::PtRay> rays) {
  if (rays.empty()) throw std::invalid_argument("Raycaster::set_rays: no rays");
  count_ = std::uint32_t(rays.size());
  rays_ = gpu::Buffer(ctx_, {rays.size_bytes(), gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal, "pt.rays"});
  rays_.upload(rays);
  hits_ = gpu::Buffer(ctx_, {rays.size() * sizeof(shaders::PtHitRecord), gpu::BufferUsage::Storage,
                             gpu::Memory::DeviceLocal, "pt.hits"});
  set_ = gpu::DescriptorSet(ctx_, pipeline_.set_layout(0));
  set_.bind(PT_BINDING_NODES, scene_.nodes()).bind(PT_BINDING_TRIS, scene_.triangles());
  set_.bind(RAYCAST_BINDING_RAYS, rays_).bind(RAYCAST_BINDING_HITS, hits_);
}

std::vector<shaders::PtHitRecord> Raycaster::trace(RayQuery query, int repeat) {
  if (count_ == 0) throw std::logic_error("Raycaster::trace before set_rays");
  gpu::GpuTimer timer(ctx_, 2);
  ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
    timer.begin(cmd);
    const shaders::PtRaycastParams p{count_, static_cast<std::uint32_t>(query), 0, 0};
    for (int r = 0; r < repeat; ++r) {
      if (r) gpu::barrier(cmd, gpu::access::compute_write, gpu::access::compute_write);
      if (scene_.tracing() == Tracing::RayQuery) pipeline_.run(cmd, {&set_, &scene_.ray_query_set()}, p, count_);
      else pipeline_.run(cmd, {&set_}, p, count_);
    }
    timer.stage(cmd, "raycast");
  });
  const auto t = timer.read();
  last_gpu_ns_ = t && !t->empty() ? t->back().duration_ns() : 0;
  return hits_.download<shaders::PtHitRecord>();
}

}  // namespace fovea::renderer
