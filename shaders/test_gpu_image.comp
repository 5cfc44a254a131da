#version 460
// Test shader for the gpu module: reads a storage image and a sampled image, writes
// out = uint(src.r) + 1000 * uint(src.g) + uint(tex.b) + add at every pixel.
layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Push {
  uint width;
  uint height;
  uint add;
} pc;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D src;
layout(set = 0, binding = 1) uniform sampler2D tex;
layout(set = 0, binding = 2, r32ui) writeonly uniform uimage2D dst;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
  vec4 a = imageLoad(src, p);
  vec4 b = texelFetch(tex, p, 0);
  imageStore(dst, p, uvec4(uint(a.r) + 1000u * uint(a.g) + uint(b.b) + pc.add));
}
