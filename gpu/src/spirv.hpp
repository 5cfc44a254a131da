#pragma once
// Just enough SPIR-V parsing to learn a compute shader's workgroup size.
#include <array>
#include <cstdint>
#include <span>

#include "fovea/gpu/pipeline.hpp"

namespace fovea::gpu::spirv {

// Workgroup size of the (single) compute entry point, with specialization constants
// applied: the WorkgroupSize built-in if present, else LocalSizeId, else LocalSize.
// Throws core::InputError for malformed SPIR-V.
std::array<std::uint32_t, 3> workgroup_size(std::span<const std::uint32_t> words,
                                            std::span<const SpecConstant> specialization);

}  // namespace fovea::gpu::spirv
