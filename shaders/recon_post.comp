#version 460
// BMFR Phase III, first half (Koskela et al. 2019 §3.5): the fitted (demodulated) frame is
// accumulated again through the same reprojection taps and accept decisions as Phase I, with
// α = max(1/n, α_min) (CMA start, then EMA with 10% new data). Without denoising the
// Phase I result passes through.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_POST_POS) readonly buffer Pos { vec4 vpos[]; };
layout(std430, binding = RECON_POST_TAP_IDX) readonly buffer TapIdx { uvec4 tap_idx[]; };
layout(std430, binding = RECON_POST_TAP_W) readonly buffer TapW { vec4 tap_w[]; };
layout(std430, binding = RECON_POST_SOURCE) readonly buffer Source { vec4 source[]; };  // fitted, or z without BMFR
layout(std430, binding = RECON_POST_ACC_DIRECT) readonly buffer AccDirect { vec4 acc_direct[]; };  // .w: Phase I count
layout(std430, binding = RECON_POST_PREV) readonly buffer PrevPost { vec4 prev_post[]; };
layout(std430, binding = RECON_POST_OUT) writeonly buffer Post { vec4 post[]; };

layout(push_constant) uniform Push { ReconPostPush pc; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.cells) return;
  if (rg_no_sample(vpos[i].w)) {
    post[i] = vec4(0.0);
    return;
  }
  vec3 c = source[i].rgb;
  if (pc.denoise == 0u || pc.has_history == 0u) {
    post[i] = vec4(c, 1.0);
    return;
  }
  vec4 w = tap_w[i];
  uvec4 idx = tap_idx[i];
  float wsum = w.x + w.y + w.z + w.w;
  vec3 h = vec3(0.0);
  for (int k = 0; k < 4; ++k) h += w[k] * prev_post[idx[k]].rgb;
  float n = wsum > 0.0 ? acc_direct[i].w : 1.0;
  float a = max(1.0 / max(n, 1.0), pc.alpha_min);
  post[i] = vec4(wsum > 0.0 ? mix(h, c, a) : c, 1.0);
}
