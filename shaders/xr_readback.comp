#version 460
// The Fovea runtime's compositor reads a submitted swapchain image by sampling it (the
// usage it adds to every colour swapchain, as compositors do), never by a transfer the
// application did not ask for: out[y * width + x] = the texel at (offset + (x, y)) of the
// array layer, as the image view decodes it (sRGB formats to linear, BGRA swizzled).
#extension GL_GOOGLE_include_directive : require
#include "fovea/shaders/xr_readback.h"

layout(local_size_x = kReadbackGroup, local_size_y = kReadbackGroup) in;

layout(push_constant) uniform Push { ReadbackPush pc; };

layout(set = 0, binding = READBACK_BINDING_SOURCE) uniform sampler2DArray src;
layout(std430, set = 0, binding = READBACK_BINDING_OUT) writeonly buffer Out { vec4 texels[]; };

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  texels[p.y * pc.width + p.x] = texelFetch(src, ivec3(int(p.x) + pc.offset_x, int(p.y) + pc.offset_y, int(pc.layer)), 0);
}
