#version 460
// Display pixels' first hits: for each pixel of a window of the display raster, rays at the
// centres of its grid × grid strata, their first hits' mean base colour (each textured over its
// stratum) and the material of the ray nearest the pixel's centre.
// Conventions: fovea/shaders/pt_primary.h.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers
#include "fovea/shaders/common.h"
#include "fovea/shaders/pt_scene.h"
#include "fovea/shaders/pt_primary.h"
#include "fovea/shaders/pt_trace.h"  // kPtSpecTextures
#include "fovea/shaders/pt_bindings.h"

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = PT_BINDING_NODES) uniform utextureBuffer nodes;  // PtBvhNode: pt_node()
layout(set = 0, binding = PT_BINDING_TRIS) uniform utextureBuffer tris;   // PtTriangle: pt_tri()
layout(set = 0, binding = PRIMARY_BINDING_SHADING) uniform textureBuffer shading;
layout(set = 0, binding = PRIMARY_BINDING_MATERIALS) uniform textureBuffer materials;
layout(std430, set = 0, binding = PRIMARY_BINDING_TEX_TABLE) readonly buffer TexTable { PtTextureInfo tex_table[]; };
layout(set = 0, binding = PRIMARY_BINDING_TEXELS) uniform utextureBuffer texels;
layout(std430, set = 0, binding = PRIMARY_BINDING_OUT) writeonly buffer Out { vec4 out_primary[]; };
layout(push_constant) uniform Params { PtPrimaryParams pc; };
layout(constant_id = kPtSpecTextures) const bool kTextures = true;

#include "fovea/shaders/pt_traverse.h"
#include "fovea/shaders/pt_rayquery.h"
#include "fovea/shaders/pt_surface.h"

void main() {
  const uvec2 w = gl_GlobalInvocationID.xy;
  if (w.x >= pc.width || w.y >= pc.height) return;
  const mat3 rot = mat3(vec3(pc.rot0_x, pc.rot0_y, pc.rot0_z), vec3(pc.rot1_x, pc.rot1_y, pc.rot1_z),
                        vec3(pc.rot2_x, pc.rot2_y, pc.rot2_z));
  const vec3 org = vec3(pc.origin_x, pc.origin_y, pc.origin_z);
  const uint n = max(pc.grid, 1u);
  // Each ray's texture cone covers its stratum: the pixel's box filter, as a converged
  // jittered raster's (point samples at the pixel centres alone alias a fine texture into moiré).
  const float step = pc.texture_cone * sqrt(pc.pixel_tx * pc.pixel_ty) / float(n);
  vec3 sum = vec3(0.0);
  float material = kPtPrimaryNoHit;
  for (uint k = 0u; k < n * n; ++k) {
    const vec2 px = vec2(pc.x0 + w.x, pc.y0 + w.y) + (vec2(k % n, k / n) + 0.5) / float(n);
    const vec3 dv = normalize(vec3(pc.tan_left + px.x * pc.pixel_tx, pc.tan_up - px.y * pc.pixel_ty, -1.0));
    const vec3 dir = normalize(rot * dv);
    PtHit h;
    if (!pt_trace_ray(org, dir, 0.0, kPtInf, false, h)) continue;
    const Surface s = surface(h, org, dir, pt_cone_spread(step, dv) * h.t);
    if (!any(isnan(s.base)) && !any(isinf(s.base))) sum += s.base;
    if (k == (n * n) / 2u) material = float(s.material);
  }
  out_primary[w.y * pc.width + w.x] = vec4(sum / float(n * n), material);
}
