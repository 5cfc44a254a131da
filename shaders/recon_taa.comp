#version 460
// Albedo re-modulation and TAA in grid space (Koskela et al. 2019 §3.5, Karis 2014; P5 §3.3:
// in Visual-Polar space, since screen-space TAA would jitter too much in the fovea): the
// reprojected history (same taps as Phase I) is clamped to the YCoCg min/max of the cell's
// 3×3 grid neighbourhood (neighbouring columns at the same φ) and blended with α_taa.
// .w = 1 marks cells holding a sample (the resolve renormalises over them).
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/pt_trace.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(std430, binding = RECON_TABLES) readonly buffer Tables { GridColumn tables[]; };
layout(std430, binding = RECON_TAA_POS) readonly buffer Pos { vec4 vpos[]; };
layout(std430, binding = RECON_TAA_TAP_IDX) readonly buffer TapIdx { uvec4 tap_idx[]; };
layout(std430, binding = RECON_TAA_TAP_W) readonly buffer TapW { vec4 tap_w[]; };
layout(std430, binding = RECON_TAA_POST) readonly buffer Post { vec4 post[]; };
layout(std430, binding = RECON_TAA_ALBEDO) readonly buffer Albedo { vec4 albedo[]; };
layout(std430, binding = RECON_TAA_PREV_FINAL) readonly buffer PrevFinal { vec4 prev_final[]; };
layout(std430, binding = RECON_TAA_FINAL) writeonly buffer Final { vec4 final_color[]; };

#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconPostPush pc; };

vec3 to_ycocg(vec3 c) {
  return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}
vec3 from_ycocg(vec3 y) { return vec3(y.x + y.y - y.z, y.x + y.z, y.x - y.y - y.z); }

vec3 remodulated(uint i) { return post[i].rgb * max(albedo[i].rgb, vec3(kPtMinDemodAlbedo)); }

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.cells) return;
  if (rg_no_sample(vpos[i].w)) {
    final_color[i] = vec4(0.0);
    return;
  }
  vec3 c = remodulated(i);
  vec4 w = tap_w[i];
  float wsum = w.x + w.y + w.z + w.w;
  if (pc.denoise == 0u || pc.has_history == 0u || wsum <= 0.0) {
    final_color[i] = vec4(c, 1.0);
    return;
  }
  ReconGrid m = maps[kReconCurrent];
  vec3 lo = vec3(3.0e38), hi = vec3(-3.0e38);
  RgCell cell = rg_cell(m, i);
  for (int dc = -1; dc <= 1; ++dc)
    for (int dr = -1; dr <= 1; ++dr) {
      uint j;
      if (!rg_neighbour_of(m, cell, dc, dr, j) || rg_no_sample(vpos[j].w)) continue;
      vec3 y = to_ycocg(remodulated(j));
      lo = min(lo, y);
      hi = max(hi, y);
    }
  uvec4 idx = tap_idx[i];
  vec3 h = vec3(0.0);
  for (int k = 0; k < 4; ++k) h += w[k] * prev_final[idx[k]].rgb;
  h = from_ycocg(clamp(to_ycocg(h), lo, hi));
  final_color[i] = vec4(max(mix(h, c, pc.taa_alpha), vec3(0.0)), 1.0);
}
