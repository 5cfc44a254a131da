#version 460
// BMFR Phase III, first half (Koskela et al. 2019 §3.5): the fitted (demodulated) indirect
// diffuse is accumulated again through the same reprojection taps and accept decisions as
// Phase I; the sum for TAA adds the fit's outlier excess and Phase I's direct+specular.
// Deviations from Koskela, measured in docs/reconstruction.md (glossy-spheres):
// - Direct light (reflections, glossy highlights, contact shadows) never enters the
//   regression, whose features [1, n, w, w²] cannot represent it; it keeps Phase I's
//   accumulation and is added back here.
// - Each frame's fit weighs by the samples behind its input (fitted.w, Phase I's count)
//   instead of equally (CMA α = 1/n): α = n / (W + n), W the history's accumulated weight
//   (post.w), floored at α_min (EMA, 10% new data). The first frames' fits, of 1–2 samples
//   per cell, spread their blocks' noise over whole surfaces; with equal weights frame 0
//   still weighed 5% after 16 frames, with count weights 0.7%. The history keeps the share
//   Phase I kept of its own (cell-size test, the landing's cap, rounding of the counts).
// - The outlier excess (recon_bmfr_fit.comp) is already Phase I's temporal mean: accumulated
//   again it would outlive the same firefly without BMFR several times over.
// Without denoising the Phase I result (direct + indirect) passes through.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers

layout(local_size_x = 64) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/recon_grid.h"

layout(binding = RECON_POST_POS) uniform textureBuffer vpos;
layout(binding = RECON_POST_TAP_IDX) uniform utextureBuffer tap_idx;
layout(binding = RECON_POST_TAP_W) uniform textureBuffer tap_w;
layout(binding = RECON_POST_SOURCE) uniform textureBuffer source;  // fitted indirect, or z without BMFR
layout(binding = RECON_POST_ACC_DIRECT) uniform textureBuffer acc_direct;  // .w: Phase I count
layout(binding = RECON_POST_PREV) uniform textureBuffer prev_post;  // accumulated fit, .w weight
layout(std430, binding = RECON_POST_OUT) writeonly buffer Post { vec4 post[]; };
layout(binding = RECON_POST_PREV_ACC_DIRECT) uniform textureBuffer prev_acc_direct;
layout(binding = RECON_POST_EXCESS) uniform textureBuffer excess;  // unread without BMFR
layout(std430, binding = RECON_POST_SUM) writeonly buffer Sum { vec4 sum[]; };          // TAA's input
layout(binding = RECON_POST_FRAME_DIRECT) uniform textureBuffer frame_direct;  // .w: this frame's samples

layout(push_constant) uniform Push { ReconPostPush pc; };
#define LIVE_CELLS_LAYOUT layout(std430, binding = RECON_POST_LIVE)
#include "fovea/shaders/live_cells.h"

void main() {
  const uint i = cell_of_invocation(pc.cells, pc.listed != 0u);
  if (i == kNoLiveCell) return;
  if (rg_no_sample(texelFetch(vpos, int(i)).w) || pc.denoise == 0u) {
    post[i] = vec4(0.0);
    sum[i] = rg_no_sample(texelFetch(vpos, int(i)).w) ? vec4(0.0) : vec4(texelFetch(source, int(i)).rgb, 1.0);
    return;
  }
  vec3 c = texelFetch(source, int(i)).rgb;
  float n = max(texelFetch(source, int(i)).w, 1.0);
  vec4 acc = vec4(c, n);
  vec4 w = texelFetch(tap_w, int(i));
  if (pc.has_history != 0u && w.x + w.y + w.z + w.w > 0.0) {
    uvec4 idx = texelFetch(tap_idx, int(i));
    vec3 h = vec3(0.0);
    float hw = 0.0, hd = 0.0;  // the history's weight; Phase I's direct count before its share
    for (int k = 0; k < 4; ++k) {
      vec4 p = texelFetch(prev_post, int(idx[k]));
      h += w[k] * p.rgb;
      hw += w[k] * p.w;
      hd += w[k] * texelFetch(prev_acc_direct, int(idx[k])).w;
    }
    // Phase I's count less this frame's samples (more than one in a new fovea's first
    // frames) is the history it kept: a landing's 8 samples counted as history kept most
    // of the old periphery's fit here while Phase I had dropped it.
    const float held = max(texelFetch(frame_direct, int(i)).w, 1.0);
    hw *= hd > 0.0 ? clamp((texelFetch(acc_direct, int(i)).w - held) / hd, 0.0, 1.0) : 0.0;
    float a = max(n / (hw + n), pc.alpha_min);
    acc = vec4(mix(h, c, a), n / a);
  }
  post[i] = acc;
  vec4 direct = texelFetch(acc_direct, int(i));
  sum[i] = vec4(acc.rgb + texelFetch(excess, int(i)).rgb + direct.rgb, direct.w);  // .w: TAA's CMA start
}
