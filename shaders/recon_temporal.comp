#version 460
// Temporal error of the display image on the device, so that a render reads back only the
// frames it writes: the mean over pixels of |Y_t - Y_(t-1)|, Y the linear luminance
// (Rec. 709 weights, non-finite channels as 0), as core::temporal_error computes it on the
// host. Each invocation adds its pixels' differences to its own running sum (no atomics: the
// result is deterministic); the host adds the sums once, in double.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers

// One invocation per run of kReconTemporalRun pixels of a row: no shared memory or barriers, which a CPU
// device pays for per workgroup (a 16x16 reduction cost lavapipe more than reading the
// images back on the tiny display).
layout(local_size_x = 64) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/recon_grid.h"

layout(binding = RECON_TEMPORAL_SCREEN) uniform textureBuffer screen;
layout(std430, binding = RECON_TEMPORAL_PREV) buffer Prev { float prev[]; };
layout(std430, binding = RECON_TEMPORAL_SUMS) buffer Sums { float sums[]; };

layout(push_constant) uniform Push { ReconTemporalPush pc; };

float finite_or_zero(float x) { return isnan(x) || isinf(x) ? 0.0 : x; }

void main() {
  uint runs = (pc.width + kReconTemporalRun - 1u) / kReconTemporalRun;
  uint id = gl_GlobalInvocationID.x;
  if (id >= runs * pc.height) return;
  uint y = id / runs, x0 = (id - y * runs) * kReconTemporalRun;
  uint x1 = min(x0 + kReconTemporalRun, pc.width);
  float s = 0.0;
  for (uint x = x0; x < x1; ++x) {
    uint i = y * pc.width + x;
    vec4 c = texelFetch(screen, int(i));
    float l = 0.2126 * finite_or_zero(c.r) + 0.7152 * finite_or_zero(c.g) + 0.0722 * finite_or_zero(c.b);
    s += abs(l - prev[i]);
    prev[i] = l;
  }
  if (pc.accumulate != 0u) sums[id] += s;
}
