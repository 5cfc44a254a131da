#pragma once
// Descriptor set layouts from a binding list (binding number = position in the list,
// one descriptor each) and descriptor sets, each with its own small pool. Sets are
// created at setup time, updated with bind(), and bound by ComputePipeline.
#include <cstdint>
#include <span>
#include <vector>

#include "fovea/gpu/handle.hpp"

namespace fovea::gpu {

class Context;
class Buffer;
class Image2D;
class Sampler;
class TriangleAccel;

enum class Binding {
  StorageBuffer,  // buffer { ... }
  UniformBuffer,  // uniform { ... }
  StorageImage,   // image2D / uimage2D with a format qualifier
  SampledImage,   // sampler2D (combined image sampler)
  AccelerationStructure,  // accelerationStructureEXT (the top level of a TriangleAccel)
  TexelBuffer,            // textureBuffer / utextureBuffer (a Buffer with a texel_format)
};
const char* binding_name(Binding b);  // "storage buffer", ... for messages

// One buffer for one binding: typed binding structs list theirs (binding indices from the
// constants the shader's layout(binding = ...) uses).
struct BufferSlot {
  std::uint32_t binding = 0;
  const Buffer* buffer = nullptr;
};

class DescriptorSetLayout {
 public:
  DescriptorSetLayout() = default;
  DescriptorSetLayout(Context& ctx, std::vector<Binding> bindings);
  VkDescriptorSetLayout handle() const { return layout_.get(); }
  const std::vector<Binding>& bindings() const { return bindings_; }

 private:
  std::vector<Binding> bindings_;
  DeviceHandle<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout> layout_;
};

class DescriptorSet {
 public:
  DescriptorSet() = default;
  // Vulkan requires `layout` to stay alive while the set is updated with bind().
  DescriptorSet(Context& ctx, const DescriptorSetLayout& layout);

  VkDescriptorSet handle() const { return set_; }

  // Point a binding at a resource. Throws core::InputError when the binding does not
  // exist or has another type. Resources must outlive every use of the set. A buffer goes
  // to a storage, uniform or texel-buffer binding (the last: its whole texel view, which it
  // must have; offset and range apply to the others).
  DescriptorSet& bind(std::uint32_t binding, const Buffer& buffer, VkDeviceSize offset = 0,
                      VkDeviceSize range = VK_WHOLE_SIZE);
  DescriptorSet& bind(std::uint32_t binding, const Image2D& image);
  // Binds every slot; throws core::InputError naming the binding unless the slots cover each
  // binding of the layout exactly once with a buffer.
  DescriptorSet& bind_all(std::span<const BufferSlot> slots);
  DescriptorSet& bind(std::uint32_t binding, const Image2D& image, const Sampler& sampler);
  DescriptorSet& bind(std::uint32_t binding, const TriangleAccel& accel);

 private:
  void expect(std::uint32_t binding, Binding type) const;
  void write(std::uint32_t binding, const VkDescriptorBufferInfo* buffer, const VkDescriptorImageInfo* image,
             const void* next = nullptr, const VkBufferView* texel = nullptr);

  std::vector<Binding> bindings_;
  DeviceHandle<VkDescriptorPool, vkDestroyDescriptorPool> pool_;
  VkDescriptorSet set_ = VK_NULL_HANDLE;  // freed with the pool
};

}  // namespace fovea::gpu
