#pragma once
// A scene on the GPU: BVH nodes, triangles in BVH order, shading attributes, materials,
// the emissive-triangle table for next-event estimation, the textures and the GGX albedo
// table of the layered BSDF, uploaded once; on devices with ray queries also the
// acceleration structure over the same triangles.
#include <cstdint>
#include <memory>
#include <string_view>

#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/renderer/bvh.hpp"
#include "fovea/renderer/scene.hpp"

namespace fovea::gpu {
class TriangleAccel;
}

namespace fovea::renderer {

// How the tracers find hits: Auto = ray queries (VK_KHR_ray_query through an acceleration
// structure) when the device offers them, else the compute BVH traversal (pt_traverse.h).
enum class Tracing { Auto, RayQuery, Compute };
// "auto", "rayquery", "compute"; anything else: core::InputError naming `what`.
Tracing parse_tracing(std::string_view s, std::string_view what = "--trace");
const char* tracing_name(Tracing t);

struct GpuSceneStats {
  std::uint32_t triangles = 0, nodes = 0, lights = 0, textures = 0;
  int bvh_depth = 0;
  double bvh_sah_cost = 0;
  bool bvh_ray_guided = false;  // the tree built for the scene's rays was kept (bvh.hpp)
  double bvh_ray_cost = 0, bvh_sah_ray_cost = 0;  // Bvh::ray_cost, sah_ray_cost
  double build_ms = 0;  // CPU BVH build
  double accel_build_ms = 0;       // acceleration-structure build (ray queries), wall clock
  std::uint64_t accel_bytes = 0;   // its storage, both levels
};

// Shading features a scene uses; the path tracer compiles a variant without the others.
struct SceneFeatures {
  bool textures = true;  // a material has a base-colour texture
  bool glossy = true;    // a material has a specular lobe (F0 > 0: specular or metallic > 0)
  bool emitters = true;  // a material emits (emission, next-event estimation)
  bool operator==(const SceneFeatures&) const = default;
  // Everything `other` uses is on here.
  bool covers(const SceneFeatures& other) const {
    return (textures || !other.textures) && (glossy || !other.glossy) && (emitters || !other.emitters);
  }
};

class GpuScene {
 public:
  // `scene` must be sanitised (every loader does that). Tracing::RayQuery on a device
  // without ray queries throws core::InputError.
  GpuScene(gpu::Context& ctx, const Scene& scene, const BvhOptions& bvh = {}, Tracing tracing = Tracing::Auto);
  ~GpuScene();

  // nodes, triangles (R32G32B32A32_UINT), shading, materials, lights, ggx_albedo
  // (R32G32B32A32_SFLOAT) and texels (R32_UINT) are also texel buffers, as the tracers read them.
  const gpu::Buffer& nodes() const { return nodes_; }
  const gpu::Buffer& triangles() const { return triangles_; }
  const gpu::Buffer& shading() const { return shading_; }
  const gpu::Buffer& materials() const { return materials_; }
  const gpu::Buffer& lights() const { return lights_; }          // >= 1 entry (a dummy when none)
  const gpu::Buffer& texture_table() const { return texture_table_; }
  const gpu::Buffer& texels() const { return texels_; }
  const gpu::Buffer& ggx_albedo() const { return ggx_albedo_; }  // layered BSDF table (pt_scene.h)
  std::uint32_t light_count() const { return stats_.lights; }     // real emissive triangles
  glm::vec3 environment() const { return environment_; }
  const GpuSceneStats& stats() const { return stats_; }
  // Resolved: RayQuery or Compute. With RayQuery the tracers use the *.rayquery.comp.spv
  // shaders and bind ray_query_set() as set 1.
  Tracing tracing() const { return accel_ ? Tracing::RayQuery : Tracing::Compute; }
  const gpu::DescriptorSet& ray_query_set() const { return accel_set_; }
  const SceneFeatures& features() const { return features_; }
  // Traversal stack entries this tree needs (specialization constant kPtSpecBvhStack):
  // at most 3 deferred children per 4-wide level (pt_traverse.h).
  std::uint32_t bvh_stack() const { return 3u * std::uint32_t(stats_.bvh_depth > 0 ? stats_.bvh_depth : 1); }
  // The device's shared memory per workgroup (kPtSpecSharedBytes): where the stack fits,
  // the traversal keeps it there.
  std::uint32_t shared_memory_bytes() const { return shared_memory_bytes_; }

 private:
  gpu::Buffer nodes_, triangles_, shading_, materials_, lights_, texture_table_, texels_, ggx_albedo_;
  glm::vec3 environment_{0};
  GpuSceneStats stats_;
  std::uint32_t shared_memory_bytes_ = 0;
  std::unique_ptr<gpu::TriangleAccel> accel_;  // null: compute traversal
  gpu::DescriptorSetLayout accel_layout_;
  gpu::DescriptorSet accel_set_;
  SceneFeatures features_;
};

}  // namespace fovea::renderer
