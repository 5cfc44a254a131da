#version 460
// BMFR Phase III, first half (Koskela et al. 2019 §3.5): the fitted (demodulated) indirect
// diffuse is accumulated again through the same reprojection taps and accept decisions as
// Phase I, with α = max(1/n, α_min) (CMA start, then EMA with 10% new data), and Phase I's
// direct+specular is added back. Deviation from Koskela: direct light (reflections, glossy
// highlights, contact shadows) never enters the regression, whose features [1, n, w, w²]
// cannot represent it (docs/reconstruction.md has the measurements); it keeps its own
// temporal accumulation. The history of this pass holds the sum, so the indirect part of
// a tap is its sum minus that tap's Phase I direct of the previous frame.
// Without denoising the Phase I result (direct + indirect) passes through.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_POST_POS) readonly buffer Pos { vec4 vpos[]; };
layout(std430, binding = RECON_POST_TAP_IDX) readonly buffer TapIdx { uvec4 tap_idx[]; };
layout(std430, binding = RECON_POST_TAP_W) readonly buffer TapW { vec4 tap_w[]; };
layout(std430, binding = RECON_POST_SOURCE) readonly buffer Source { vec4 source[]; };  // fitted indirect, or z without BMFR
layout(std430, binding = RECON_POST_ACC_DIRECT) readonly buffer AccDirect { vec4 acc_direct[]; };  // .w: Phase I count
layout(std430, binding = RECON_POST_PREV) readonly buffer PrevPost { vec4 prev_post[]; };
layout(std430, binding = RECON_POST_OUT) writeonly buffer Post { vec4 post[]; };
layout(std430, binding = RECON_POST_PREV_ACC_DIRECT) readonly buffer PrevAccDirect { vec4 prev_acc_direct[]; };

layout(push_constant) uniform Push { ReconPostPush pc; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.cells) return;
  if (rg_no_sample(vpos[i].w)) {
    post[i] = vec4(0.0);
    return;
  }
  vec3 c = source[i].rgb;
  if (pc.denoise == 0u) {
    post[i] = vec4(c, 1.0);
    return;
  }
  vec3 direct = acc_direct[i].rgb;
  vec4 w = tap_w[i];
  float wsum = w.x + w.y + w.z + w.w;
  if (pc.has_history == 0u || wsum <= 0.0) {
    post[i] = vec4(c + direct, 1.0);
    return;
  }
  uvec4 idx = tap_idx[i];
  vec3 h = vec3(0.0);
  for (int k = 0; k < 4; ++k) h += w[k] * max(prev_post[idx[k]].rgb - prev_acc_direct[idx[k]].rgb, vec3(0.0));
  float a = max(1.0 / max(acc_direct[i].w, 1.0), pc.alpha_min);
  post[i] = vec4(mix(h, c, a) + direct, 1.0);
}
