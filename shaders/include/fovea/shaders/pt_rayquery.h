// GLSL only: pt_trace_ray, the scene query the tracers call. Compiled with FOVEA_RAYQUERY
// (the *.rayquery.comp.spv variants) it asks the device's acceleration structure through
// GL_EXT_ray_query (set 1, binding PT_BINDING_TLAS: the top level of the scene's TriangleAccel, whose
// primitive i is pt_tri(i)); otherwise it is pt_traverse, the compute BVH traversal.
// Include after pt_traverse.h. Same semantics either way: closest hit, or any hit when
// any_hit (shadow rays stop at the first); both faces; every triangle opaque (no alpha
// test); hit.bary the weights of vertices 1 and 2; hits within (tmin, tmax) (ray queries close
// the interval, a difference only for hits exactly at an end, which the callers' origin
// offsets and shortened shadow rays keep away).
#ifndef FOVEA_SHADERS_PT_RAYQUERY_H
#define FOVEA_SHADERS_PT_RAYQUERY_H
#include "fovea/shaders/pt_bindings.h"

#ifdef FOVEA_RAYQUERY
#extension GL_EXT_ray_query : require
layout(set = 1, binding = PT_BINDING_TLAS) uniform accelerationStructureEXT pt_scene_tlas;

bool pt_trace_ray(vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, out PtHit hit) {
  hit.t = tmax;
  hit.tri = kPtNoHit;
  hit.bary = vec2(0.0);
  rayQueryEXT q;
  const uint flags = gl_RayFlagsOpaqueEXT | (any_hit ? gl_RayFlagsTerminateOnFirstHitEXT : 0u);
  rayQueryInitializeEXT(q, pt_scene_tlas, flags, 0xFFu, org, tmin, dir, tmax);
  while (rayQueryProceedEXT(q)) {
  }  // opaque geometry only: no candidate is left for the shader to confirm
  if (rayQueryGetIntersectionTypeEXT(q, true) != gl_RayQueryCommittedIntersectionTriangleEXT) return false;
  hit.t = rayQueryGetIntersectionTEXT(q, true);
  hit.tri = uint(rayQueryGetIntersectionPrimitiveIndexEXT(q, true));
  hit.bary = rayQueryGetIntersectionBarycentricsEXT(q, true);
  return true;
}
#else
bool pt_trace_ray(vec3 org, vec3 dir, float tmin, float tmax, bool any_hit, out PtHit hit) {
  return pt_traverse(org, dir, tmin, tmax, any_hit, hit);
}
#endif

#endif
