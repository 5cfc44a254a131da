#pragma once
// Acceleration structures for ray queries (needs EnabledFeatures::ray_query): a bottom
// level over non-indexed triangles and a top level holding it once with the identity
// transform, both built on the device at construction.
#include <span>

#include "fovea/gpu/buffer.hpp"

namespace fovea::gpu {

class TriangleAccel {
 public:
  TriangleAccel() = default;
  // `vertices`: x, y, z per vertex, three vertices per triangle; a ray query's primitive
  // index i is triangle i. Every triangle is opaque (no any-hit candidates to confirm)
  // and both faces are hit. Throws core::InputError when the context has no ray queries
  // or there are no triangles.
  TriangleAccel(Context& ctx, std::span<const float> vertices);
  ~TriangleAccel();
  TriangleAccel(TriangleAccel&& o) noexcept;
  TriangleAccel& operator=(TriangleAccel&& o) noexcept;

  VkAccelerationStructureKHR top() const { return top_; }
  VkDeviceSize bytes() const { return bottom_storage_.size() + top_storage_.size(); }  // both levels

 private:
  void release();

  VkDevice device_ = VK_NULL_HANDLE;
  PFN_vkDestroyAccelerationStructureKHR destroy_ = nullptr;
  Buffer bottom_storage_, top_storage_;
  VkAccelerationStructureKHR bottom_ = VK_NULL_HANDLE, top_ = VK_NULL_HANDLE;
};

}  // namespace fovea::gpu
