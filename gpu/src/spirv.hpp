#pragma once
// Just enough SPIR-V parsing to learn a compute shader's workgroup size and the descriptor
// bindings it declares.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "fovea/gpu/pipeline.hpp"

namespace fovea::gpu::spirv {

// Workgroup size of the (single) compute entry point, with specialization constants
// applied: the WorkgroupSize built-in if present, else LocalSizeId, else LocalSize.
// Throws core::InputError for malformed SPIR-V.
std::array<std::uint32_t, 3> workgroup_size(std::span<const std::uint32_t> words,
                                            std::span<const SpecConstant> specialization);

struct DeclaredBinding {
  std::uint32_t set = 0, binding = 0;
  Binding type = Binding::StorageBuffer;
};
// Every resource variable the module declares with a descriptor set and binding, ordered by
// (set, binding). Throws core::InputError for malformed SPIR-V or a resource type the
// pipelines do not bind (anything but buffers, storage images and combined samplers).
std::vector<DeclaredBinding> descriptor_bindings(std::span<const std::uint32_t> words);

}  // namespace fovea::gpu::spirv
