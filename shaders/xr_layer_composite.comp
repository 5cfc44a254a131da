#version 450
// The API layer's composition on the application's device (fovea/shaders/layer_composite.h):
// the same steps, in the same order, as the host path's resample(), composite() and
// composite_depth() in layer/src/composite.cpp, on packed 8-bit pixels, so kept pixels stay
// bit-exact; blends decode with the host's table and encode with the sRGB formula (within one
// 8-bit step); depths compare in 32-bit floats (the host in doubles).
#extension GL_GOOGLE_include_directive : require
#include "fovea/shaders/layer_composite.h"

// Workgroup size: specialisation constants 1 and 2 (the border pass: kLayerBorderGroup
// invocations; the composite pass larger groups, fewer of them for lavapipe to schedule).
layout(local_size_x_id = 1, local_size_y_id = 2) in;

// The pass, a specialisation constant: each pass is its own pipeline, so the composite pass
// is compiled without the border pass's workgroup barriers (which make lavapipe run a
// workgroup's invocations as coroutines).
layout(constant_id = 0) const uint kPass = kLayerPassComposite;

layout(push_constant) uniform Push {
  uint eye;
} pc;

layout(std430, set = 0, binding = LAYER_BINDING_PARAMS) readonly buffer Params { LayerCompositeParams p; };
layout(std430, set = 0, binding = LAYER_BINDING_TRACED) readonly buffer Traced { uint traced[]; };
layout(std430, set = 0, binding = LAYER_BINDING_APP) readonly buffer App { uint app[]; };
layout(std430, set = 0, binding = LAYER_BINDING_OUT) writeonly buffer Out { uint outp[]; };
layout(std430, set = 0, binding = LAYER_BINDING_BACKGROUND) buffer Background { uint background[2]; };
layout(std430, set = 0, binding = LAYER_BINDING_APP_DEPTH) readonly buffer AppDepth { uint app_depth[]; };

shared uint best_count[kLayerBorderGroup];
shared uint best_key[kLayerBorderGroup];

// A view's tangent-plane extents (left, right, up, down) as a vector: loaded once per
// invocation instead of passing arrays by value.
vec4 tangents(float t[4]) { return vec4(t[0], t[1], t[2], t[3]); }

// View::pixel_to_dir of pixel centre (x, y) (unnormalised: only ratios are used).
vec3 pixel_dir(vec4 tan, int w, int h, int x, int y) {
  return vec3(tan.x + ((float(x) + 0.5) / float(w)) * (tan.y - tan.x),
              tan.z - ((float(y) + 0.5) / float(h)) * (tan.z - tan.w), -1.0);
}

// View::dir_to_pixel followed by resample()'s bounds check: the texel index, -1 outside.
int dir_texel(vec4 tan, int w, int h, vec3 d) {
  if (!(d.z < 0.0)) return -1;
  float tx = d.x / -d.z, ty = d.y / -d.z;
  float px = (tx - tan.x) / (tan.y - tan.x) * float(w);
  float py = (tan.z - ty) / (tan.z - tan.w) * float(h);
  if (!(px >= 0.0) || !(py >= 0.0) || px >= float(w) || py >= float(h)) return -1;
  return int(py) * w + int(px);
}

// The i-th pixel border_colour() counts (rows 0 and h-1 whole, then the side columns
// between them), as its key: the first three bytes.
uint border_key(uint i, int w, int h, uint base) {
  int x, y;
  if (i < uint(w)) {
    x = int(i);
    y = 0;
  } else if (i < uint(2 * w)) {
    x = int(i) - w;
    y = h - 1;
  } else {
    int k = int(i) - 2 * w;
    x = (k & 1) == 0 ? 0 : w - 1;
    y = 1 + k / 2;
  }
  return app[base + uint(y * w + x)] & 0xffffffu;
}

uint channel(uint v, int c) { return (v >> (8 * c)) & 255u; }

uint encode(float v) {
  v = clamp(v, 0.0, 1.0);
  if (p.srgb != 0u) v = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
  return uint(floor(v * 255.0 + 0.5));
}

// The application's window depth at `texel` of its depth rect, decoded as the host's
// read_depth() does.
float window_depth(LayerCompositeEye pe, int texel) {
  uint fmt = pe.depth_format;
  if (fmt == kLayerDepthD16) {
    uint byte_offset = pe.depth_offset + uint(texel) * 2u;
    return float((app_depth[byte_offset >> 2] >> (8u * (byte_offset & 2u))) & 0xffffu) / 65535.0;
  }
  uint word = app_depth[(pe.depth_offset >> 2) + uint(texel)];
  if (fmt == kLayerDepthD24) return float(word & 0xffffffu) / 16777215.0;
  float v = uintBitsToFloat(word);
  return isnan(v) || isinf(v) ? 1.0 : v;
}

// composite_depth() for one pixel: whether the application's pixel `a` (at `app_texel`) is
// nearer than the traced scene (at `traced_texel`; -1: not covered, as far as the sky).
// Distances compare as their inverses, which the depth range maps to linearly (view_distance()
// in composite.cpp): no infinities.
bool app_nearer(LayerCompositeEye pe, uint a, int app_texel, int traced_texel) {
  if (channel(a, 3) == 0u) return false;  // also where the application's rect does not reach
  float d = window_depth(pe, app_texel);
  float lo = pe.min_depth, hi = pe.max_depth;
  // The cleared far end (maxDepth, minDepth with reversed Z): the application drew nothing.
  bool reversed = pe.inv_near < pe.inv_far;
  if (reversed ? d <= lo : d >= hi) return false;
  float t = clamp((d - lo) / (hi - lo), 0.0, 1.0);
  float inv_app = (1.0 - t) * pe.inv_near + t * pe.inv_far;
  float scene = traced_texel >= 0 ? uintBitsToFloat(traced[pe.traced_depth_offset + uint(traced_texel)]) : 0.0;
  float inv_scene = scene > 0.0 ? 1.0 / scene : 0.0;  // 0: the sky, infinitely far
  return inv_app > inv_scene;
}

void border_pass(uint e) {
  int w = p.eye[e].app_w, h = p.eye[e].app_h;
  uint base = p.eye[e].app_offset;
  // border_colour(): both rows whole, then the side columns between them.
  uint n = uint(2 * w + 2 * max(h - 2, 0));
  uint tid = gl_LocalInvocationIndex;
  uint my_count = 0u, my_key = 0xffffffffu;
  for (uint i = tid; i < n; i += kLayerBorderGroup) {
    uint key = border_key(i, w, h, base);
    // Counted once, at the colour's first border pixel: a border mostly of the clear colour
    // (the usual case) costs O(n), not O(n^2).
    bool first = true;
    for (uint j = 0u; j < i && first; ++j) first = border_key(j, w, h, base) != key;
    if (!first) continue;
    uint count = 1u;
    for (uint j = i + 1u; j < n; ++j) count += border_key(j, w, h, base) == key ? 1u : 0u;
    if (count > my_count || (count == my_count && key < my_key)) {
      my_count = count;
      my_key = key;
    }
  }
  best_count[tid] = my_count;
  best_key[tid] = my_key;
  barrier();
  // Most frequent, ties to the smallest key (std::map order + max_element's first maximum).
  for (uint s = kLayerBorderGroup / 2u; s > 0u; s >>= 1) {
    if (tid < s) {
      uint c = best_count[tid + s], k = best_key[tid + s];
      if (c > best_count[tid] || (c == best_count[tid] && k < best_key[tid])) {
        best_count[tid] = c;
        best_key[tid] = k;
      }
    }
    barrier();
  }
  if (tid == 0u) background[e] = n == 0u ? 0u : best_key[0];
}

// One output pixel of eye `pe` (p.eye[e], loaded once per invocation).
uint composite_pixel(uint e, LayerCompositeEye pe, int x, int y) {
  int o = y * pe.out_w + x;
  vec4 out_tan = tangents(pe.out_tan);
  vec3 d = pixel_dir(out_tan, pe.out_w, pe.out_h, x, y);
  // resample(traced, traced_view, out_view, to_traced); uncovered: black.
  int traced_texel = o;
  if (pe.traced_identity == 0u) {
    vec3 rd = vec3(dot(vec3(pe.to_traced[0], pe.to_traced[1], pe.to_traced[2]), d),
                   dot(vec3(pe.to_traced[3], pe.to_traced[4], pe.to_traced[5]), d),
                   dot(vec3(pe.to_traced[6], pe.to_traced[7], pe.to_traced[8]), d));
    traced_texel = dir_texel(tangents(pe.traced_tan), pe.traced_w, pe.traced_h, rd);
  }
  uint s = traced_texel >= 0 ? traced[pe.traced_offset + uint(traced_texel)] : 0u;
  s = (s & 0xffffffu) | 0xff000000u;
  if (p.mode == kLayerSceneOnly) return s;
  // resample(app, app_view, out_view): the application's FOV at its own raster.
  int app_texel = pe.app_identity != 0u ? o : dir_texel(out_tan, pe.app_w, pe.app_h, d);
  uint a = app_texel >= 0 ? app[pe.app_offset + uint(app_texel)] : 0u;
  uint alpha = channel(a, 3);
  if (p.mode == kLayerDepth) {
    // The depths travel with their colour: the same texels (resample_depth()).
    return app_nearer(pe, a, app_texel, traced_texel) ? a : s;
  }
  if (p.mode == kLayerAppOnTop) {
    uint bg = p.auto_background != 0u ? background[e] : p.background;
    bool differs = false;
    for (int c = 0; c < 3; ++c) differs = differs || abs(int(channel(a, c)) - int(channel(bg, c))) > p.tolerance;
    return alpha != 0u && differs ? a : s;
  }
  if (p.source_alpha == 0u) alpha = 255u;
  bool adds = (a & 0xffffffu) != 0u;
  if (alpha == 255u) return (a & 0xffffffu) | 0xff000000u;
  if (alpha == 0u && !(p.premultiplied != 0u && adds)) return s;
  // Premultiplied: out = src + (1 - a) dst; straight: out = a src + (1 - a) dst.
  float fa = float(alpha) / 255.0;
  float src_weight = p.premultiplied != 0u ? 1.0 : fa;
  uint blended = 0xff000000u;
  for (int c = 0; c < 3; ++c)
    blended |= encode(src_weight * p.decode[channel(a, c)] + (1.0 - fa) * p.decode[channel(s, c)]) << (8 * c);
  return blended;
}

// kLayerRowsPerInvocation rows of one column: the eye's parameters are loaded once for them.
void composite_pass(uint e) {
  LayerCompositeEye pe = p.eye[e];
  int x = int(gl_GlobalInvocationID.x);
  if (x >= pe.out_w) return;
  for (int k = 0; k < int(kLayerRowsPerInvocation); ++k) {
    int y = int(gl_GlobalInvocationID.y) * int(kLayerRowsPerInvocation) + k;
    if (y >= pe.out_h) return;
    outp[pe.out_offset + uint(y * pe.out_w + x)] = composite_pixel(e, pe, x, y);
  }
}

void main() {
  if (kPass == kLayerPassBorder)
    border_pass(pc.eye);
  else
    composite_pass(pc.eye);
}
