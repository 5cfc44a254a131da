// Integer hashing shared by C++ and GLSL so CPU references and shaders draw the same
// random numbers (e.g. which pixels linear fall-off kills).
#ifndef FOVEA_SHADERS_HASH_H
#define FOVEA_SHADERS_HASH_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

// A 32-bit avalanche mix (xor-shift / multiply rounds).
FOVEA_FN FOVEA_UINT hash1(FOVEA_UINT x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

FOVEA_FN FOVEA_UINT hash3(FOVEA_UINT a, FOVEA_UINT b, FOVEA_UINT c) { return hash1(a ^ hash1(b ^ hash1(c))); }

// Top 24 bits as a float in [0, 1): exact in float32, so CPU and GPU agree bit for bit.
FOVEA_FN float hash_to_unit(FOVEA_UINT h) { return float(h >> 8) * (1.0f / 16777216.0f); }

#ifdef __cplusplus
}  // namespace fovea::shaders
#endif
#endif
