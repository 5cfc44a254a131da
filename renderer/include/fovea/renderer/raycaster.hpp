#pragma once
// Batches of rays against a GpuScene (pt_raycast.comp): closest-hit or any-hit, through
// the scene's tracing (ray queries or the compute BVH, GpuScene::tracing()) or by brute
// force. For BVH tests and the ray-throughput benchmark.
#include <span>
#include <vector>

#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/shaders/pt_raycast.h"

namespace fovea::renderer {

enum class RayQuery : std::uint32_t {
  Closest = shaders::kPtRaycastClosest,
  Any = shaders::kPtRaycastAny,
  BruteClosest = shaders::kPtRaycastBruteClosest,
  BruteAny = shaders::kPtRaycastBruteAny,
};

// Means per ray of the compute traversal's work for closest-hit queries: node visits and
// triangle tests, and the most any ray of the same subgroup needed (the lockstep cost on
// SIMD devices such as lavapipe, where a subgroup runs as one vector of rays).
struct TraversalStats {
  double nodes = 0, triangles = 0, subgroup_nodes = 0, subgroup_triangles = 0;
};

class Raycaster {
 public:
  // count_traversal: trace() reports work counters instead of hits (traversal_stats());
  // needs the compute traversal (std::invalid_argument with ray queries).
  Raycaster(gpu::Context& ctx, const GpuScene& scene, bool count_traversal = false);

  // Uploads `rays` (replacing earlier ones); trace() then runs on them.
  void set_rays(std::span<const shaders::PtRay> rays);
  // Traces the current rays `repeat` times in one submission; returns the hits.
  std::vector<shaders::PtHitRecord> trace(RayQuery query, int repeat = 1);
  // Closest-hit work over the current rays (a Raycaster made with count_traversal).
  TraversalStats traversal_stats();
  // GPU time of the last trace() in ns (0 without timestamp support).
  std::int64_t last_gpu_ns() const { return last_gpu_ns_; }

 private:
  gpu::Context& ctx_;
  const GpuScene& scene_;
  bool count_traversal_;
  gpu::ComputePipeline pipeline_;
  gpu::Buffer rays_, hits_;
  gpu::DescriptorSet set_;
  std::uint32_t count_ = 0;
  std::int64_t last_gpu_ns_ = 0;
};

}  // namespace fovea::renderer
