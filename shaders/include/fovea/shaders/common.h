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
#endif
#endif
