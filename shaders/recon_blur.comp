#version 460
// Peripheral blur (P5 §3.5): one pass of a separable Gaussian on the display whose σ follows
// the acuity model: σ(e) = σ_fovea / m(e) degrees (reconstruct::blur_sigma_deg; m of P4
// Eq. 1 as core::acuity::m), converted to pixels with the local pixel density along the pass
// direction, so it carries across displays. Pixels whose σ is below min_sigma_px are copied.
// Weights renormalise at the raster's border.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(std430, binding = RECON_TABLES) readonly buffer Tables { GridColumn tables[]; };
layout(std430, binding = RECON_BLUR_SRC) readonly buffer Src { vec4 src[]; };
layout(std430, binding = RECON_BLUR_DST) writeonly buffer Dst { vec4 dst[]; };

#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconBlurPush pc; };

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  ReconGrid m = maps[kReconCurrent];
  vec2 px = vec2(p) + 0.5;
  vec3 d = rg_pixel_to_dir(m, px);
  vec3 g = rg_gaze(m);
  uint i = p.y * pc.width + p.x;
  if (dot(d, g) > pc.cos_skip) {  // near the gaze: σ < min_sigma_px on any pixel of this raster
    dst[i] = src[i];
    return;
  }
  float e = atan(length(cross(d, g)), dot(d, g)) * (180.0 / kRgPi);
  // Local pixels per degree along the pass direction: finite difference of the angle.
  vec2 step_px = pc.vertical != 0u ? vec2(0.0, 1.0) : vec2(1.0, 0.0);
  vec3 d1 = rg_pixel_to_dir(m, px + step_px);
  float deg_per_px = atan(length(cross(d, d1)), dot(d, d1)) * (180.0 / kRgPi);
  float acuity = e <= 5.79 ? 1.0 : 7.49 / ((0.3 * e + 1.0) * (0.3 * e + 1.0));
  float sigma = min(pc.sigma_fovea_deg / acuity / max(deg_per_px, 1e-6), pc.max_sigma_px);
  if (sigma < pc.min_sigma_px) {
    dst[i] = src[i];
    return;
  }
  int radius = int(ceil(3.0 * sigma));
  int pos = int(pc.vertical != 0u ? p.y : p.x);
  int n = int(pc.vertical != 0u ? pc.height : pc.width);
  vec4 acc = vec4(0.0);
  float wsum = 0.0;
  for (int k = max(-radius, -pos); k <= min(radius, n - 1 - pos); ++k) {
    float w = exp(-0.5 * float(k * k) / (sigma * sigma));
    uint j = pc.vertical != 0u ? uint(pos + k) * pc.width + p.x : p.y * pc.width + uint(pos + k);
    acc += w * src[j];
    wsum += w;
  }
  dst[i] = acc / wsum;
}
