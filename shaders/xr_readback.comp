#version 460
// The Fovea runtime's compositor reads a submitted swapchain image by sampling it (the
// usage it adds to every colour swapchain, as compositors do), never by a transfer the
// application did not ask for: out[y * width + x] = the texel at (offset + (x, y)) of the
// array layer, as the image view decodes it (sRGB formats to linear, BGRA swizzled).
layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
  int offset_x;
  int offset_y;
  uint width;
  uint height;
  uint layer;
} pc;

layout(set = 0, binding = 0) uniform sampler2DArray src;
layout(std430, set = 0, binding = 1) writeonly buffer Out { vec4 texels[]; };

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  texels[p.y * pc.width + p.x] = texelFetch(src, ivec3(int(p.x) + pc.offset_x, int(p.y) + pc.offset_y, int(pc.layer)), 0);
}
