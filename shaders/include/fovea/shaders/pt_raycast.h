// Ray batches for pt_raycast.comp (BVH tests and ray-throughput benchmarks). Shared C++/GLSL.
#ifndef FOVEA_SHADERS_PT_RAYCAST_H
#define FOVEA_SHADERS_PT_RAYCAST_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

FOVEA_CONST FOVEA_UINT kPtRaycastClosest = 0;       // BVH, closest hit
FOVEA_CONST FOVEA_UINT kPtRaycastAny = 1;           // BVH, any hit (shadow query)
FOVEA_CONST FOVEA_UINT kPtRaycastBruteClosest = 2;  // every triangle, closest hit
FOVEA_CONST FOVEA_UINT kPtRaycastBruteAny = 3;      // every triangle, any hit

struct PtRay {
  float org_x, org_y, org_z, tmin;
  float dir_x, dir_y, dir_z, tmax;
};

// triangle: the scene triangle index (PtTriangle::source), kPtNoHit on a miss; any-hit
// queries report 0 for "occluded". u, v: barycentric weights of vertices 1 and 2.
struct PtHitRecord {
  float t;
  FOVEA_UINT triangle;
  float u, v;
};

struct PtRaycastParams {
  FOVEA_UINT count, mode, pad0, pad1;
};

#ifdef __cplusplus
static_assert(sizeof(PtRay) == 32 && sizeof(PtHitRecord) == 16 && sizeof(PtRaycastParams) == 16);
}  // namespace fovea::shaders
#endif
#endif
