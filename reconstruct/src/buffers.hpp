#pragma once
// Buffer and pipeline helpers shared by the reconstruction stages.
#include <algorithm>
#include <cstdint>
#include <string>

#include "fovea/core/error.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/shaders/live_cells.h"

namespace fovea::reconstruct {

inline gpu::Buffer storage(gpu::Context& ctx, VkDeviceSize bytes, const char* name,
                           gpu::Memory memory = gpu::Memory::DeviceLocal) {
  return gpu::Buffer(ctx, {.size = std::max<VkDeviceSize>(bytes, 16), .usage = gpu::BufferUsage::Storage,
                           .memory = memory, .name = name});
}

// Per-cell data that later kernels read as texels (`textureBuffer` / `utextureBuffer`,
// texelFetch) and their producer writes as a storage buffer: vec4 (RGBA32F) by default.
inline gpu::Buffer cells(gpu::Context& ctx, std::uint32_t count, const char* name,
                         VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT) {
  const VkDeviceSize bytes = VkDeviceSize(count) * gpu::texel_buffer_bytes(format);
  return gpu::Buffer(ctx, {.size = std::max<VkDeviceSize>(bytes, 16),
                           .usage = gpu::BufferUsage::Storage, .name = name, .texel_format = format});
}

// A kernel with `Bindings::kCount` bindings, each the type the shader declares (storage or
// texel buffer; gpu::declared_bindings), all in set 0.
template <class Bindings, class Push>
gpu::ComputePipeline kernel(gpu::Context& ctx, const char* shader, std::vector<gpu::SpecConstant> spec = {}) {
  std::vector<gpu::Binding> set = gpu::declared_bindings(shader);
  if (set.size() != Bindings::kCount)
    throw core::InputError(std::string(shader) + " declares " + std::to_string(set.size()) + " bindings, its binding struct " +
                           std::to_string(Bindings::kCount));
  return gpu::ComputePipeline(ctx, {.shader = shader, .sets = {std::move(set)}, .push_constant_bytes = sizeof(Push),
                                    .specialization = std::move(spec)});
}

// The grid pass's live-tile list of an eye (EyeGrid::live), which every per-cell kernel binds.
inline const gpu::Buffer& live_list(const gpu::Buffer* live) {
  if (!live) throw core::InputError("reconstruction: the eye's grid has no live-tile list (EyeGrid::live)");
  return *live;
}

// Records a per-cell kernel (bound with `set`, its push's `listed` set) over an eye's cells:
// the cells of the live-tile list's live and reset tiles, an indirect dispatch, or all `cells`.
template <class Push>
void run_cells(VkCommandBuffer cmd, const gpu::ComputePipeline& k, const gpu::DescriptorSet& set, const Push& push,
               std::uint32_t cells, const gpu::Buffer* live) {
  k.bind(cmd, {&set});
  k.push(cmd, push);
  if (push.listed) k.dispatch_indirect(cmd, live_list(live), shaders::kLiveArgsChanged * sizeof(std::uint32_t));
  else k.dispatch_linear(cmd, cells);
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
