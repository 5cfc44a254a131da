#version 450
// Display-stage distortion pass (compositor/distortion.hpp): per panel pixel, three
// bilinear taps of the resolved view (one per colour channel at that channel's source
// position through the lens), black in the hidden area, explicit linear → sRGB encode.
// The optics are evaluated directly per pixel, or read from the optional LUT cache.
#extension GL_GOOGLE_include_directive : require
#include "fovea/shaders/distortion_bindings.h"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = DISTORT_BINDING_SOURCE, rgba32f) uniform readonly image2D source_image;
layout(set = 0, binding = DISTORT_BINDING_PANEL, rgba8) uniform writeonly image2D panel_image;
// Per channel 16 floats (compositor/src/distortion.cpp, pack_optics): display centre (2),
// to-radial scale (2), source centre (2), from-radial scale (2), Vive-profile flag, k0..k4,
// edge radius, padding.
layout(set = 0, binding = DISTORT_BINDING_OPTICS, std430) readonly buffer Optics { float optics[48]; };
// Hidden-area bitmask, words_per_row 32-bit words per row, bit set = hidden.
layout(set = 0, binding = DISTORT_BINDING_MASK, std430) readonly buffer Mask { uint mask_words[]; };
// Optional optics cache (core/lens_lut.hpp): lut_size² nodes spanning the panel, per node
// and channel the source uv, float pair at ((j·N + i)·3 + c)·2.
layout(set = 0, binding = DISTORT_BINDING_LUT, std430) readonly buffer Lut { float lut[]; };

layout(push_constant) uniform Push {
  uint width, height;          // panel
  uint src_width, src_height;  // view image
  uint select;                 // 3: each channel its own optics; 0..2: that channel's for all
  uint words_per_row;
  uint lut_size;               // 0: direct evaluation; else N of the LUT
} pc;

float k(int c, int i) { return optics[c * 16 + i]; }

// R(r) of lens.cpp's profile(); beyond the edge the edge's scale continues.
float profile(int c, float r) {
  r = min(r, k(c, 14));
  if (k(c, 8) > 0.5) {
    float r2 = r * r;
    return 1.0 / (1.0 + r2 * (k(c, 9) + r2 * (k(c, 10) + r2 * k(c, 11)))) + k(c, 12);
  }
  return k(c, 9) + r * (k(c, 10) + r * (k(c, 11) + r * (k(c, 12) + r * k(c, 13))));
}

vec2 source_uv(int c, vec2 uv) {
  vec2 t = (uv - vec2(k(c, 0), k(c, 1))) * vec2(k(c, 2), k(c, 3));
  return vec2(k(c, 4), k(c, 5)) + vec2(k(c, 6), k(c, 7)) * t * profile(c, length(t));
}

vec2 lut_node(int c, ivec2 ij) {
  int b = ((ij.y * int(pc.lut_size) + ij.x) * 3 + c) * 2;
  return vec2(lut[b], lut[b + 1]);
}

// Bilinear in the LUT, as LensLut::source_uv.
vec2 lut_source_uv(int c, vec2 uv) {
  float n1 = float(pc.lut_size - 1u);
  vec2 p = clamp(uv, 0.0, 1.0) * n1;
  vec2 i0 = min(floor(p), vec2(n1 - 1.0));
  vec2 f = p - i0;
  ivec2 q = ivec2(i0);
  vec2 top = mix(lut_node(c, q), lut_node(c, q + ivec2(1, 0)), f.x);
  vec2 bottom = mix(lut_node(c, q + ivec2(0, 1)), lut_node(c, q + ivec2(1, 1)), f.x);
  return mix(top, bottom, f.y);
}

// Non-finite texels are black, huge ones bounded so the filter cannot overflow.
vec4 texel(ivec2 p) {
  p = clamp(p, ivec2(0), ivec2(pc.src_width, pc.src_height) - 1);
  vec4 v = imageLoad(source_image, p);
  bvec4 bad = bvec4(isnan(v).x || isinf(v).x, isnan(v).y || isinf(v).y, isnan(v).z || isinf(v).z,
                    isnan(v).w || isinf(v).w);
  return clamp(mix(v, vec4(0.0), bad), 0.0, 1e6);
}

// Bilinear tap of channel c at source uv (texel centres at +0.5, clamp to edge).
float tap(int c, vec2 uv) {
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 0.0;
  vec2 p = uv * vec2(pc.src_width, pc.src_height) - 0.5;
  vec2 i0 = floor(p);
  vec2 f = p - i0;
  ivec2 q = ivec2(i0);
  float a = texel(q)[c], b = texel(q + ivec2(1, 0))[c];
  float d = texel(q + ivec2(0, 1))[c], e = texel(q + ivec2(1, 1))[c];
  return mix(mix(a, b, f.x), mix(d, e, f.x), f.y);
}

float srgb_encode(float x) {
  x = clamp(x, 0.0, 1.0);
  return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

void main() {
  uvec2 id = gl_GlobalInvocationID.xy;
  if (id.x >= pc.width || id.y >= pc.height) return;
  vec4 out_value = vec4(0.0, 0.0, 0.0, 1.0);
  bool hidden = ((mask_words[id.y * pc.words_per_row + (id.x >> 5)] >> (id.x & 31u)) & 1u) != 0u;
  if (!hidden) {
    vec2 uv = (vec2(id) + 0.5) / vec2(pc.width, pc.height);
    for (int c = 0; c < 3; ++c) {
      int optic = pc.select == 3u ? c : int(pc.select);
      vec2 src = pc.lut_size > 0u ? lut_source_uv(optic, uv) : source_uv(optic, uv);
      out_value[c] = srgb_encode(tap(c, src));
    }
  }
  imageStore(panel_image, ivec2(id), out_value);
}
