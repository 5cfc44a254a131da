#pragma once
// Buffer and pipeline helpers shared by the reconstruction stages.
#include <algorithm>
#include <cstdint>

#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"

namespace fovea::reconstruct {

inline gpu::Buffer storage(gpu::Context& ctx, VkDeviceSize bytes, const char* name,
                           gpu::Memory memory = gpu::Memory::DeviceLocal) {
  return gpu::Buffer(ctx, {.size = std::max<VkDeviceSize>(bytes, 16), .usage = gpu::BufferUsage::Storage,
                           .memory = memory, .name = name});
}

// A kernel whose bindings are all storage buffers, `Bindings::kCount` of them.
template <class Bindings, class Push>
gpu::ComputePipeline kernel(gpu::Context& ctx, const char* shader, std::vector<gpu::SpecConstant> spec = {}) {
  return gpu::ComputePipeline(
      ctx, {.shader = shader, .sets = {std::vector<gpu::Binding>(Bindings::kCount, gpu::Binding::StorageBuffer)},
            .push_constant_bytes = sizeof(Push), .specialization = std::move(spec)});
}

// A descriptor set of `p` with every binding of a typed binding struct.
template <class Bindings>
gpu::DescriptorSet make_set(gpu::Context& ctx, const gpu::ComputePipeline& p, const Bindings& b) {
  gpu::DescriptorSet set(ctx, p.set_layout(0));
  const auto slots = b.slots();
  set.bind_all(slots);
  return set;
}

}  // namespace fovea::reconstruct
