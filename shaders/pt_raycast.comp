#version 460
// Traces a batch of rays against the scene BVH (or by brute force): BVH tests and the
// ray-throughput benchmark.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers
#ifdef FOVEA_TRAVERSE_STATS
#extension GL_KHR_shader_subgroup_arithmetic : require
#endif
#include "fovea/shaders/pt_order.h"
#include "fovea/shaders/pt_scene.h"
#include "fovea/shaders/pt_raycast.h"
#include "fovea/shaders/pt_bindings.h"

layout(local_size_x = 64) in;
layout(set = 0, binding = PT_BINDING_NODES) uniform utextureBuffer nodes;  // PtBvhNode: pt_node()
layout(set = 0, binding = PT_BINDING_TRIS) uniform utextureBuffer tris;   // PtTriangle: pt_tri()
layout(std430, set = 0, binding = RAYCAST_BINDING_RAYS) readonly buffer Rays { PtRay rays[]; };
layout(std430, set = 0, binding = RAYCAST_BINDING_HITS) writeonly buffer Hits { PtHitRecord hits[]; };
layout(push_constant) uniform Params { PtRaycastParams pc; };

#include "fovea/shaders/pt_traverse.h"
#include "fovea/shaders/pt_rayquery.h"

void main() {
  // Whole workgroups take their 64 rays in pt_order.h's strip order: llvmpipe gives each of
  // its threads a contiguous part of the dispatch, which in the rays' own order (a raster's
  // rows) is the top or the bottom of the image, rarely equal work; the strips give every
  // part the same share of each region. Rays and hits keep their indices.
  const uint blocks = pc.count / 64u, w = gl_WorkGroupID.x;
  const uint i = w < blocks ? pt_tile_of_workgroup(w, blocks) * 64u + gl_LocalInvocationID.x : gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  const PtRay ray = rays[i];
  const vec3 org = vec3(ray.org_x, ray.org_y, ray.org_z), dir = vec3(ray.dir_x, ray.dir_y, ray.dir_z);
  const bool any_hit = pc.mode == kPtRaycastAny || pc.mode == kPtRaycastBruteAny;
  PtHit h;
  bool found;
  if (pc.mode == kPtRaycastClosest || pc.mode == kPtRaycastAny) found = pt_trace_ray(org, dir, ray.tmin, ray.tmax, any_hit, h);
  else found = pt_brute_force(org, dir, ray.tmin, ray.tmax, any_hit, h);
  PtHitRecord rec;
  rec.t = found ? h.t : ray.tmax;
  rec.triangle = found ? (any_hit ? 0u : pt_tri(h.tri).source) : kPtNoHit;
  rec.u = found && !any_hit ? h.bary.x : 0.0;
  rec.v = found && !any_hit ? h.bary.y : 0.0;
#ifdef FOVEA_TRAVERSE_STATS
  // This ray's node visits and triangle tests, and the most of any ray in its subgroup
  // (what a SIMD device pays when the subgroup's rays run in lockstep).
  rec = PtHitRecord(float(pt_stat_nodes), pt_stat_tris, float(subgroupMax(pt_stat_nodes)), float(subgroupMax(pt_stat_tris)));
#endif
  hits[i] = rec;
}
