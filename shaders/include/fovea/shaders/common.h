// Shared between C++ and GLSL: type spellings so one struct definition serves both.
// Only 4-byte scalars in shared structs: their std430 layout equals the C++ layout.
#ifndef FOVEA_SHADERS_COMMON_H
#define FOVEA_SHADERS_COMMON_H
#ifdef __cplusplus
#include <cstdint>
#define FOVEA_UINT std::uint32_t
#define FOVEA_INT std::int32_t
#define FOVEA_CONST constexpr
#define FOVEA_FN inline  // a function shared by C++ and GLSL
#else
#define FOVEA_UINT uint
#define FOVEA_INT int
#define FOVEA_CONST const
#define FOVEA_FN
// The index of this invocation in a 1-D dispatch of gpu::ComputePipeline::dispatch_linear,
// which folds more workgroups than the device allows in x into rows of groups; without a
// fold it equals gl_GlobalInvocationID.x. A macro: gl_WorkGroupSize is known only after the
// shader's local_size declaration.
#define FOVEA_LINEAR_INVOCATION \
  ((gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x + gl_LocalInvocationID.x)
#endif
#endif
