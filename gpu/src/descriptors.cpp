#include "fovea/gpu/descriptors.hpp"

#include <map>
#include <string>

#include "fovea/core/error.hpp"
#include "fovea/gpu/accel.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/error.hpp"
#include "fovea/gpu/image.hpp"

namespace fovea::gpu {
namespace {

VkDescriptorType vk_type(Binding b) {
  switch (b) {
    case Binding::StorageBuffer: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    case Binding::UniformBuffer: return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    case Binding::StorageImage: return VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    case Binding::SampledImage: return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    case Binding::AccelerationStructure: return VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
    case Binding::TexelBuffer: return VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
  }
  return VK_DESCRIPTOR_TYPE_MAX_ENUM;
}

}  // namespace

const char* binding_name(Binding b) {
  switch (b) {
    case Binding::StorageBuffer: return "storage buffer";
    case Binding::UniformBuffer: return "uniform buffer";
    case Binding::StorageImage: return "storage image";
    case Binding::SampledImage: return "sampled image";
    case Binding::AccelerationStructure: return "acceleration structure";
    case Binding::TexelBuffer: return "texel buffer";
  }
  return "?";
}

DescriptorSetLayout::DescriptorSetLayout(Context& ctx, std::vector<Binding> bindings) : bindings_(std::move(bindings)) {
  std::vector<VkDescriptorSetLayoutBinding> vk(bindings_.size());
  for (std::size_t i = 0; i < bindings_.size(); ++i) {
    vk[i].binding = static_cast<std::uint32_t>(i);
    vk[i].descriptorType = vk_type(bindings_[i]);
    vk[i].descriptorCount = 1;
    vk[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  ci.bindingCount = static_cast<std::uint32_t>(vk.size());
  ci.pBindings = vk.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  check(vkCreateDescriptorSetLayout(ctx.device(), &ci, nullptr, &layout), "vkCreateDescriptorSetLayout");
  layout_ = {ctx.device(), layout};
}

DescriptorSet::DescriptorSet(Context& ctx, const DescriptorSetLayout& layout) : bindings_(layout.bindings()) {
  std::map<VkDescriptorType, std::uint32_t> counts;
  for (Binding b : bindings_) ++counts[vk_type(b)];
  std::vector<VkDescriptorPoolSize> sizes;
  for (auto [type, n] : counts) sizes.push_back({type, n});
  VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pci.maxSets = 1;
  pci.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
  pci.pPoolSizes = sizes.data();
  VkDescriptorPool pool = VK_NULL_HANDLE;
  check(vkCreateDescriptorPool(ctx.device(), &pci, nullptr, &pool), "vkCreateDescriptorPool");
  pool_ = {ctx.device(), pool};

  const VkDescriptorSetLayout l = layout.handle();
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &l;
  check(vkAllocateDescriptorSets(ctx.device(), &ai, &set_), "vkAllocateDescriptorSets");
}

void DescriptorSet::expect(std::uint32_t binding, Binding type) const {
  if (binding >= bindings_.size())
    throw core::InputError("gpu::DescriptorSet::bind: binding " + std::to_string(binding) + " does not exist (the layout has " +
                           std::to_string(bindings_.size()) + ")");
  if (bindings_[binding] != type)
    throw core::InputError("gpu::DescriptorSet::bind: binding " + std::to_string(binding) + " is a " +
                           binding_name(bindings_[binding]) + ", not a " + binding_name(type));
}

DescriptorSet& DescriptorSet::bind(std::uint32_t binding, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize range) {
  const Binding type = binding < bindings_.size() ? bindings_[binding] : Binding::StorageBuffer;
  if (type == Binding::TexelBuffer) {
    const VkBufferView view = buffer.texel_view();
    if (view == VK_NULL_HANDLE)
      throw core::InputError("gpu::DescriptorSet::bind: binding " + std::to_string(binding) +
                             " is a texel buffer, and the buffer has no texel format");
    if (offset != 0 || range != VK_WHOLE_SIZE)
      throw core::InputError("gpu::DescriptorSet::bind: binding " + std::to_string(binding) +
                             " is a texel buffer, which binds its whole buffer (no offset or range)");
    write(binding, nullptr, nullptr, nullptr, &view);
    return *this;
  }
  expect(binding, type == Binding::UniformBuffer ? Binding::UniformBuffer : Binding::StorageBuffer);
  const VkDescriptorBufferInfo info{buffer.handle(), offset, range};
  write(binding, &info, nullptr);
  return *this;
}

DescriptorSet& DescriptorSet::bind_all(std::span<const BufferSlot> slots) {
  std::vector<bool> seen(bindings_.size(), false);
  for (const BufferSlot& s : slots) {
    const std::string which = "descriptor binding " + std::to_string(s.binding);
    if (s.binding >= bindings_.size()) throw core::InputError(which + " is not in the layout");
    if (seen[s.binding]) throw core::InputError(which + " is given twice");
    if (!s.buffer) throw core::InputError(which + " has no buffer");
    seen[s.binding] = true;
  }
  for (std::size_t b = 0; b < seen.size(); ++b)
    if (!seen[b]) throw core::InputError("descriptor binding " + std::to_string(b) + " is not given");
  for (const BufferSlot& s : slots) bind(s.binding, *s.buffer);
  return *this;
}

DescriptorSet& DescriptorSet::bind(std::uint32_t binding, const Image2D& image) {
  expect(binding, Binding::StorageImage);
  const VkDescriptorImageInfo info{VK_NULL_HANDLE, image.view(), Image2D::kLayout};
  write(binding, nullptr, &info);
  return *this;
}

DescriptorSet& DescriptorSet::bind(std::uint32_t binding, const Image2D& image, const Sampler& sampler) {
  expect(binding, Binding::SampledImage);
  const VkDescriptorImageInfo info{sampler.handle(), image.view(), Image2D::kLayout};
  write(binding, nullptr, &info);
  return *this;
}

DescriptorSet& DescriptorSet::bind(std::uint32_t binding, const TriangleAccel& accel) {
  expect(binding, Binding::AccelerationStructure);
  const VkAccelerationStructureKHR top = accel.top();
  VkWriteDescriptorSetAccelerationStructureKHR info{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  info.accelerationStructureCount = 1;
  info.pAccelerationStructures = &top;
  write(binding, nullptr, nullptr, &info);
  return *this;
}

void DescriptorSet::write(std::uint32_t binding, const VkDescriptorBufferInfo* buffer,
                          const VkDescriptorImageInfo* image, const void* next, const VkBufferView* texel) {
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, next};
  w.dstSet = set_;
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = vk_type(bindings_[binding]);
  w.pBufferInfo = buffer;
  w.pImageInfo = image;
  w.pTexelBufferView = texel;
  vkUpdateDescriptorSets(pool_.device(), 1, &w, 0, nullptr);
}

}  // namespace fovea::gpu
