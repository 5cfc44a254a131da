#version 460
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers
// fovea_bench_gather (bench/gather_bench.cpp): each invocation sums `taps` vec4s of one
// buffer, read as a storage buffer or as a texel buffer (kTexel), at its own index plus a
// stride (coherent: neighbouring invocations read neighbouring elements) or at hashed
// indices within 4096 elements after its own (random: 64 KiB, cache-resident, so the read
// instructions are measured rather than cache misses), and writes the sum — what lavapipe
// pays per vec4 read either way.
layout(local_size_x = 64) in;

layout(constant_id = 0) const bool kTexel = false;

layout(std430, binding = 0) readonly buffer Src { vec4 src[]; };
layout(binding = 1) uniform textureBuffer src_texels;  // the same buffer
layout(std430, binding = 2) writeonly buffer Dst { vec4 dst[]; };
layout(push_constant) uniform Push {
  uint count, mask, taps, random;  // mask: element count - 1 (a power of two)
} pc;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  vec4 sum = vec4(0.0);
  uint h = i * 2654435761u;
  for (uint k = 0u; k < pc.taps; ++k) {
    h = h * 1664525u + 1013904223u;
    const uint j = (i + (pc.random != 0u ? h >> 20 : k * 4096u)) & pc.mask;
    sum += kTexel ? texelFetch(src_texels, int(j)) : src[j];
  }
  dst[i] = sum;
}
