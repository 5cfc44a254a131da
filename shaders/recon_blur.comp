#version 460
// Peripheral blur (P5 §3.5): one pass of a separable Gaussian on the display whose σ follows
// the acuity model: σ(e) = σ_fovea / m(e) degrees (reconstruct::blur_sigma_deg; m of P4
// Eq. 1 as core::acuity::m), converted to pixels with the local pixel density along the pass
// direction, so it carries across displays. Pixels whose σ is below min_sigma_px are copied.
// Weights renormalise at the raster's border.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers

layout(local_size_x = 8, local_size_y = 8) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(binding = RECON_TABLES) uniform textureBuffer tables;  // GridColumn: rg_table()
layout(binding = RECON_BLUR_SRC) uniform textureBuffer src;
layout(std430, binding = RECON_BLUR_DST) writeonly buffer Dst { vec4 dst[]; };

#include "fovea/shaders/recon_map.h"
#include "fovea/shaders/recon_blur.h"

layout(push_constant) uniform Push { ReconBlurPush pc; };

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  ReconGrid m = maps[kReconCurrent];
  vec2 t = rg_pixel_tan(m, vec2(p) + 0.5);
  vec3 g = rg_gaze(m);
  float cos_e = dot(vec3(t, -1.0), g) * inversesqrt(1.0 + dot(t, t));
  uint i = p.y * pc.width + p.x;
  if (cos_e > pc.cos_skip) {  // near the gaze: σ < min_sigma_px on any pixel of this raster
    dst[i] = texelFetch(src, int(i));
    return;
  }
  float e = atan(sqrt(max(1.0 - cos_e * cos_e, 0.0)), cos_e) * (180.0 / kRgPi);
  bool vertical = pc.vertical != 0u;
  float deg_per_px = rg_pixel_angle(m, t, vertical) * (180.0 / kRgPi);
  float sigma = min(rg_blur_sigma_deg(e, pc.sigma_fovea_deg) / max(deg_per_px, 1e-6), pc.max_sigma_px);
  if (sigma < pc.min_sigma_px) {
    dst[i] = texelFetch(src, int(i));
    return;
  }
  int radius = int(ceil(3.0 * sigma));
  int pos = int(vertical ? p.y : p.x);
  int n = int(vertical ? pc.height : pc.width);
  int stride = vertical ? int(pc.width) : 1;
  // Taps ±k share the weight exp(a k²), a = -1/(2σ²), built by the recurrence
  // w_k = w_{k-1}·q_{k-1}, q_k = q_{k-1}·exp(2a) (no exp per tap).
  float a = -0.5 / (sigma * sigma);
  float w = 1.0, q = exp(a), q2 = q * q;
  vec4 acc = texelFetch(src, int(i));
  float wsum = 1.0;
  for (int k = 1; k <= radius; ++k) {
    w *= q;
    q *= q2;
    if (pos - k >= 0) {
      acc += w * texelFetch(src, int(int(i) - k * stride));
      wsum += w;
    }
    if (pos + k < n) {
      acc += w * texelFetch(src, int(int(i) + k * stride));
      wsum += w;
    }
  }
  dst[i] = acc / wsum;
}
