#version 460
// Path tracing of the per-sample rays of any sample grid (BMFR/P5 configuration by
// default: primary hit, next-event estimation to one emissive triangle chosen by power,
// one BSDF-sampled bounce, NEE again, MIS between light and BSDF sampling).
// Output layout and conventions: fovea/shaders/pt_trace.h.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers
#include "fovea/shaders/common.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/pt_scene.h"
#include "fovea/shaders/pt_trace.h"
#include "fovea/shaders/pt_order.h"
#include "fovea/shaders/pt_bindings.h"

layout(local_size_x = 64) in;  // one tile of the tile order (pt_order.h)
layout(set = 0, binding = PT_BINDING_NODES) uniform utextureBuffer nodes;  // PtBvhNode: pt_node()
layout(set = 0, binding = PT_BINDING_TRIS) uniform utextureBuffer tris;   // PtTriangle: pt_tri()
// Scene data read per path vertex are texel buffers (pt_traverse.h says why): decoded by
// pt_shading(), pt_material(), pt_light() below.
layout(set = 0, binding = PT_BINDING_SHADING) uniform textureBuffer shading;    // PtShading: 4 texels each
layout(set = 0, binding = PT_BINDING_MATERIALS) uniform textureBuffer materials;  // PtMaterial: 3 texels each
layout(set = 0, binding = PT_BINDING_LIGHTS) uniform textureBuffer lights;     // PtLight: 1 texel each
layout(std430, set = 0, binding = PT_BINDING_TEX_TABLE) readonly buffer TexTable { PtTextureInfo tex_table[]; };
layout(set = 0, binding = PT_BINDING_TEXELS) uniform utextureBuffer texels;    // RGBA8 per texel
layout(std430, set = 0, binding = PT_BINDING_GRID) readonly buffer Grid { GridSample cells[]; };
layout(std430, set = 0, binding = PT_BINDING_OUT_DIRECT) buffer OutDirect { vec4 out_direct[]; };
layout(std430, set = 0, binding = PT_BINDING_OUT_INDIRECT) buffer OutIndirect { vec4 out_indirect[]; };
layout(std430, set = 0, binding = PT_BINDING_OUT_ALBEDO) buffer OutAlbedo { vec4 out_albedo[]; };
layout(std430, set = 0, binding = PT_BINDING_OUT_NORMAL_DEPTH) buffer OutNormalDepth { vec4 out_normal_depth[]; };
layout(std430, set = 0, binding = PT_BINDING_OUT_POSITION_MATERIAL) buffer OutPosMat { vec4 out_position_material[]; };
layout(std430, set = 0, binding = PT_BINDING_OUT_RADIANCE) buffer OutRadiance { vec4 out_radiance[]; };
layout(set = 0, binding = PT_BINDING_GGX_ALBEDO) uniform textureBuffer ggx_albedo;  // read by pt_sampling.h
#define LIVE_CELLS_LAYOUT layout(std430, set = 0, binding = PT_BINDING_LIVE_LIST)
#include "fovea/shaders/live_cells.h"
layout(push_constant) uniform Params { PtFrameParams pc; };
// What the scene uses (PathTracer sets them from GpuScene::features()); false removes the
// code: base-colour textures, GGX lobes (all F0 = 0), emission and next-event estimation.
layout(constant_id = kPtSpecTextures) const bool kTextures = true;
layout(constant_id = kPtSpecGlossy) const bool kGlossy = true;
layout(constant_id = kPtSpecEmitters) const bool kEmitters = true;

#include "fovea/shaders/pt_sampling.h"
#include "fovea/shaders/pt_traverse.h"
#include "fovea/shaders/pt_rayquery.h"

const float kPtMaxValue = 1e30;  // clamp so sums of finite samples stay finite

PtShading pt_shading(uint i) {
  const int k = int(4u * i);
  const vec4 a = texelFetch(shading, k), b = texelFetch(shading, k + 1), c = texelFetch(shading, k + 2),
             d = texelFetch(shading, k + 3);
  return PtShading(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w, c.x, c.y, c.z, c.w, d.x, d.y, d.z, d.w);
}

PtMaterial pt_material(uint i) {
  const int k = int(3u * i);
  const vec4 a = texelFetch(materials, k), b = texelFetch(materials, k + 1), c = texelFetch(materials, k + 2);
  return PtMaterial(a.x, a.y, a.z, floatBitsToInt(a.w), b.x, b.y, b.z, b.w, c.x, c.y, floatBitsToUint(c.z), c.w);
}

PtLight pt_light(uint i) {
  const vec4 a = texelFetch(lights, int(i));
  return PtLight(floatBitsToUint(a.x), a.y, a.z, a.w);
}

vec3 srgb_to_linear(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), greaterThan(c, vec3(0.04045)));
}

// Texel (x, y), repeating, of the level of `size` texels at `offset`.
vec3 texel(uint offset, ivec2 size, int x, int y) {
  x = (x % size.x + size.x) % size.x;
  y = (y % size.y + size.y) % size.y;
  return srgb_to_linear(unpackUnorm4x8(texelFetch(texels, int(offset + uint(y * size.x + x))).x).rgb);
}

// Bilinear, repeating, on linear values.
vec3 bilinear(uint offset, ivec2 size, vec2 uv) {
  const vec2 p = fract(uv) * vec2(size) - 0.5;
  const vec2 f = fract(p);
  const ivec2 a = ivec2(floor(p)), b = a + 1;
  return mix(mix(texel(offset, size, a.x, a.y), texel(offset, size, b.x, a.y), f.x),
             mix(texel(offset, size, a.x, b.y), texel(offset, size, b.x, b.y), f.x), f.y);
}

// Trilinear over the texture's mip chain (GpuScene: level l of max(w >> l, 1) × max(h >> l, 1)
// texels after level l − 1) at level of detail `lod` (0: the full texture).
vec3 sample_texture(int index, vec2 uv, float lod) {
  const PtTextureInfo t = tex_table[index];
  lod = clamp(lod, 0.0, float(max(t.levels, 1u) - 1u));
  const int l0 = int(lod);
  const float f = lod - float(l0);
  uint offset = t.offset;
  ivec2 size = ivec2(t.width, t.height);
  for (int l = 0; l < l0; ++l) {
    offset += uint(size.x * size.y);
    size = max(size / 2, ivec2(1));
  }
  vec3 c = bilinear(offset, size, uv);
  if (f > 0.0) c = mix(c, bilinear(offset + uint(size.x * size.y), max(size / 2, ivec2(1)), uv), f);
  return c;
}

// Texture level of detail of a ray cone `width` wide (world units) where it meets a triangle
// (Akenine-Möller et al. 2019, "Texture Level of Detail Strategies for Real-Time Ray Tracing",
// Ray Tracing Gems ch. 20, Eq. 34): Δ0 = ½·log2(texel area / world area of the triangle) plus
// log2(width), with the footprint's stretch 1/|cos θ| taken as its area's square root
// (−½·log2|cos θ|): the full stretch blurred a grazing floor's bricks across as well (fovea
// SSIM at 16 ppd, bricks met at 8°: Cartesian 0.80 against 0.97, visual-polar 0.61 against
// 0.78; tests/pipeline/grazing_texture_test.cpp, docs/reconstruction.md).
float cone_lod(PtTextureInfo t, vec3 e1, vec3 e2, vec2 duv1, vec2 duv2, float width, float cos_theta) {
  const float world = length(cross(e1, e2));
  const float tex = float(t.width) * float(t.height) * abs(duv1.x * duv2.y - duv2.x * duv1.y);
  if (!(width > 0.0) || !(world > 0.0) || !(tex > 0.0)) return 0.0;
  return 0.5 * log2(tex / world) + log2(width) - 0.5 * log2(max(cos_theta, 1e-4));
}

struct Surface {
  vec3 p, ng, ns;  // position, geometric and shading normals, both facing the incoming ray
  bool front;      // the ray hit the front (counter-clockwise) side
  bool lit;        // front face, or a back face of a double-sided material
  uint material;
  vec3 base;
  vec3 emission;
  float light_pdf;  // P(select) / area of this triangle as a light
};

// `cone`: the ray cone's width at the hit (world units; 0: the texture's full resolution).
Surface surface(PtHit h, vec3 org, vec3 dir, float cone) {
  Surface s;
  const PtTriangle t = pt_tri(h.tri);
  const PtShading sh = pt_shading(h.tri);
  const vec3 v0 = vec3(t.v0_x, t.v0_y, t.v0_z), v1 = vec3(t.v1_x, t.v1_y, t.v1_z), v2 = vec3(t.v2_x, t.v2_y, t.v2_z);
  const float w0 = 1.0 - h.bary.x - h.bary.y;
  s.p = w0 * v0 + h.bary.x * v1 + h.bary.y * v2;
  vec3 ng = normalize(cross(v1 - v0, v2 - v0));
  s.front = dot(ng, dir) < 0.0;
  vec3 ns = w0 * vec3(sh.n0_x, sh.n0_y, sh.n0_z) + h.bary.x * vec3(sh.n1_x, sh.n1_y, sh.n1_z) +
            h.bary.y * vec3(sh.n2_x, sh.n2_y, sh.n2_z);
  ns = dot(ns, ns) > 0.0 ? normalize(ns) : ng;
  // Both normals on the viewer's side: glTF lights the back faces of double-sided materials
  // with the normal reversed (glTF 2.0 §3.9.5); single-sided back faces stay black.
  if (!s.front) ng = -ng;
  if (dot(ns, ng) < 0.0) ns = -ns;
  s.ng = ng;
  s.ns = ns;
  s.material = t.material;
  const PtMaterial m = pt_material(t.material);
  s.lit = s.front || m.double_sided != 0u;
  s.base = s.lit ? vec3(m.base_r, m.base_g, m.base_b) : vec3(0.0);
  if (kTextures && m.texture >= 0 && s.lit) {
    const vec2 uv0 = vec2(sh.uv0_x, sh.uv0_y), uv1 = vec2(sh.uv1_x, sh.uv1_y), uv2 = vec2(sh.uv2_x, sh.uv2_y);
    const vec2 uv = w0 * uv0 + h.bary.x * uv1 + h.bary.y * uv2;
    const float lod = cone_lod(tex_table[m.texture], v1 - v0, v2 - v0, uv1 - uv0, uv2 - uv0, cone, abs(dot(ng, dir)));
    s.base *= sample_texture(m.texture, uv, lod);
  }
  s.emission = s.lit ? vec3(m.emit_r, m.emit_g, m.emit_b) : vec3(0.0);
  s.light_pdf = t.light_pdf;
  return s;
}

PtBsdf bsdf_of(Surface s) {
  const PtMaterial m = pt_material(s.material);
  PtBsdf b;
  b.diffuse = s.base * (1.0 - m.metallic);
  b.f0 = kGlossy && s.lit ? mix(vec3(m.specular), s.base, m.metallic) : vec3(0.0);
  b.alpha = max(m.roughness * m.roughness, 4e-4);
  return b;
}

// Offset along the geometric normal towards `towards`, scaled with the coordinates.
vec3 offset_origin(Surface s, vec3 towards) {
  const float eps = 1e-4 * max(1.0, pt_max3(abs(s.p)));
  return s.p + (dot(s.ng, towards) >= 0.0 ? s.ng : -s.ng) * eps;
}

// Next-event estimation: one emissive triangle chosen by power, a uniform point on it.
// Returns f·cos·Le·w / pdf; `mis` weighs against BSDF sampling (false at the last vertex).
vec3 sample_light(Surface s, PtBsdf b, vec3 wo, bool mis, inout PtRng rng) {
  const float ul = pt_rand(rng), u1 = pt_rand(rng), u2 = pt_rand(rng);
  if (!kEmitters || pc.light_count == 0u) return vec3(0.0);  // after the draws: same random stream
  uint lo = 0u, hi = pc.light_count - 1u;
  while (lo < hi) {  // first light whose CDF exceeds ul
    const uint mid = (lo + hi) / 2u;
    if (texelFetch(lights, int(mid)).y > ul) hi = mid; else lo = mid + 1u;  // .y: PtLight::cdf
  }
  const PtLight l = pt_light(lo);
  const PtTriangle t = pt_tri(l.triangle);
  const vec3 v0 = vec3(t.v0_x, t.v0_y, t.v0_z), v1 = vec3(t.v1_x, t.v1_y, t.v1_z), v2 = vec3(t.v2_x, t.v2_y, t.v2_z);
  const float su = sqrt(u1);
  const vec3 q = (1.0 - su) * v0 + su * (1.0 - u2) * v1 + su * u2 * v2;
  const vec3 nl = normalize(cross(v1 - v0, v2 - v0));
  vec3 to = q - s.p;
  const float d2 = dot(to, to);
  if (!(d2 > 0.0)) return vec3(0.0);
  const float dist = sqrt(d2);
  const vec3 wi = to / dist;
  const PtMaterial lm = pt_material(t.material);
  // Single-sided emitters emit from their front face only, double-sided ones from both.
  const float cos_l = lm.double_sided != 0u ? abs(dot(nl, wi)) : -dot(nl, wi);
  if (cos_l <= 0.0 || dot(s.ng, wi) <= 0.0) return vec3(0.0);
  vec3 fd, fs;
  float bsdf_pdf;
  pt_bsdf_eval(b, s.ns, wo, wi, fd, fs, bsdf_pdf);
  const vec3 f = fd + fs;
  if (pt_max3(f) <= 0.0) return vec3(0.0);
  const vec3 org = offset_origin(s, wi);
  PtHit sh;
  if (pt_trace_ray(org, wi, 0.0, distance(q, org) * (1.0 - 1e-4), true, sh)) return vec3(0.0);
  const float light_pdf = l.pmf / l.area * d2 / cos_l;  // area -> solid angle
  const float w = mis ? pt_power_heuristic(light_pdf, bsdf_pdf) : 1.0;
  return f * vec3(lm.emit_r, lm.emit_g, lm.emit_b) * (w / light_pdf);
}

vec3 finite_or_zero(vec3 v) {
  return (any(isnan(v)) || any(isinf(v))) ? vec3(0.0) : min(v, vec3(kPtMaxValue));
}

struct Sample {
  vec3 direct, indirect;  // not yet demodulated
  vec3 albedo, normal, position;
  float depth, material;
};

// `spread`: the primary ray's cone angle (radians), its cell's angular size: the first hit
// samples its texture at that footprint; later hits at full resolution.
Sample trace_path(vec3 org, vec3 dir, vec3 forward, float spread, inout PtRng rng) {
  Sample r;
  r.direct = vec3(0.0);
  r.indirect = vec3(0.0);
  r.albedo = vec3(1.0);
  r.normal = vec3(0.0);
  r.position = vec3(0.0);
  r.depth = 0.0;
  r.material = -1.0;
  const vec3 env = vec3(pc.env_r, pc.env_g, pc.env_b);
  const uint max_bounces = min(pc.max_bounces, kPtHardMaxBounces);
  PtHit h;
  if (!pt_trace_ray(org, dir, 0.0, kPtInf, false, h)) {
    r.direct = env;
    return r;
  }
  vec3 beta = vec3(1.0);
  vec3 frac_diffuse = vec3(0.0);  // share of the path weight through x0's diffuse lobe
  float prev_pdf = 0.0;
  vec3 wo = -dir;
  for (uint k = 0u;; ++k) {
    const Surface s = surface(h, org, dir, k == 0u ? spread * h.t : 0.0);
    if (k == 0u) {
      r.albedo = s.base;
      r.normal = s.ns;
      r.position = s.p;
      r.depth = dot(s.p - org, forward);
      r.material = float(s.material);
    }
    // Emission found by BSDF sampling, MIS-weighted against NEE from the previous vertex.
    if (kEmitters && pt_max3(s.emission) > 0.0) {
      vec3 c;
      if (k == 0u) {
        c = s.emission;
      } else {
        const float d2 = h.t * h.t, cos_l = abs(dot(s.ng, dir));
        const float light_pdf = cos_l > 0.0 ? s.light_pdf * d2 / cos_l : 0.0;
        c = beta * s.emission * pt_power_heuristic(prev_pdf, light_pdf);
      }
      c = finite_or_zero(c);
      if (k <= 1u) r.direct += c;
      else { r.indirect += c * frac_diffuse; r.direct += c * (1.0 - frac_diffuse); }
    }
    const PtBsdf b = bsdf_of(s);
    const bool last = k >= max_bounces;
    // NEE at x_k is direct lighting of x_k: for x0 bucket (a); deeper, by x0's lobe.
    const vec3 nee = finite_or_zero(beta * sample_light(s, b, wo, !last, rng));
    if (k == 0u) r.direct += nee;
    else { r.indirect += nee * frac_diffuse; r.direct += nee * (1.0 - frac_diffuse); }
    if (last) break;
    if (k >= pc.rr_start) {
      const float q = min(pt_max3(beta), 0.95);
      if (!(pt_rand(rng) < q)) break;
      beta /= q;
    }
    vec3 wi;
    const vec3 u = vec3(pt_rand(rng), pt_rand(rng), pt_rand(rng));
    if (!pt_bsdf_sample(b, s.ns, wo, u, wi) || dot(s.ng, wi) <= 0.0) break;
    vec3 fd, fs;
    float pdf;
    pt_bsdf_eval(b, s.ns, wo, wi, fd, fs, pdf);
    if (!(pdf > 0.0)) break;
    const vec3 w_d = fd / pdf, w_s = fs / pdf;
    if (k == 0u) {
      const vec3 tot = w_d + w_s;
      frac_diffuse = vec3(tot.x > 0.0 ? w_d.x / tot.x : 0.0, tot.y > 0.0 ? w_d.y / tot.y : 0.0,
                          tot.z > 0.0 ? w_d.z / tot.z : 0.0);
    }
    beta *= w_d + w_s;
    if (pt_max3(beta) <= 0.0) break;
    prev_pdf = pdf;
    org = offset_origin(s, wi);
    dir = wi;
    wo = -wi;
    if (!pt_trace_ray(org, dir, 0.0, kPtInf, false, h)) {
      // The environment is not light-sampled, so BSDF sampling carries its full weight.
      const vec3 c = finite_or_zero(beta * env);
      if (k == 0u) r.direct += c;
      else { r.indirect += c * frac_diffuse; r.direct += c * (1.0 - frac_diffuse); }
      break;
    }
  }
  return r;
}

void main() {
  const uint invocation = FOVEA_LINEAR_INVOCATION;
  // The cell, not the invocation, keys the random numbers and the outputs: every order gives
  // the same buffers (the live tiles' leaves the cells without a sample as they were).
  uint idx;
  const bool listed = (pc.flags & kPtLiveList) != 0u;
  if (listed) {
    idx = live_cell(false);
    if (idx == kNoLiveCell) return;
  } else {
    if (invocation >= pc.cell_count) return;
    idx = (pc.flags & kPtTileOrder) != 0u ? pt_tile_cell(invocation, pc.columns, pc.cell_count) : invocation;
  }
  const GridSample g = cells[idx];
  const bool accumulate = (pc.flags & kPtAccumulate) != 0u && pc.accumulated_samples > 0u;
  if (g.flags != 0u) {
    if (listed) return;  // nothing reads a skipped cell's outputs in the live order
    out_direct[idx] = vec4(0.0);
    out_indirect[idx] = vec4(0.0);
    out_albedo[idx] = vec4(0.0);
    out_normal_depth[idx] = vec4(0.0);
    out_position_material[idx] = vec4(0.0, 0.0, 0.0, -1.0);
    out_radiance[idx] = vec4(0.0);
    return;
  }
  const mat3 rot = mat3(vec3(pc.rot0_x, pc.rot0_y, pc.rot0_z), vec3(pc.rot1_x, pc.rot1_y, pc.rot1_z),
                        vec3(pc.rot2_x, pc.rot2_y, pc.rot2_z));
  const vec3 org = vec3(pc.origin_x, pc.origin_y, pc.origin_z);
  const vec3 forward = rot * vec3(0.0, 0.0, -1.0);
  vec3 dv = vec3(g.dir_x, g.dir_y, g.dir_z);
  vec3 sum_d = vec3(0.0), sum_i = vec3(0.0), sum_a = vec3(0.0), sum_l = vec3(0.0);
  Sample first;
  // A new fovea's first frames (PathConfig::boost_spp): more samples near the gaze.
  const uint spp = pc.boost_spp > pc.spp && g.ecc_deg <= pc.boost_deg ? pc.boost_spp : max(pc.spp, 1u);
  // The primary ray's cone (PathConfig::texture_cone) in cells of the cell's angular size:
  // its sample spacing on the z = -1 tangent plane times cos^1.5 of the angle off the axis (a
  // tangent-plane step dt spans dt·cos² radially and dt·cos across; their geometric mean).
  const float off_axis = dv.z < 0.0 ? -dv.z : 0.0;
  const float spread = pc.texture_cone * g.footprint * sqrt(pc.pixel_tx * pc.pixel_ty) * off_axis * sqrt(off_axis);
  for (uint i = 0u; i < spp; ++i) {
    PtRng rng = pt_rng(idx, pc.frame, pc.eye, pc.sample_offset + i);
    vec3 d = dv;
    if ((pc.flags & kPtJitter) != 0u && dv.z < 0.0) {
      // Uniform over the cell's footprint on the z = -1 tangent plane.
      const vec2 j = (vec2(pt_rand(rng), pt_rand(rng)) - 0.5) * g.footprint * vec2(pc.pixel_tx, -pc.pixel_ty);
      d = normalize(vec3(dv.xy / -dv.z + j, -1.0));
    }
    const Sample s = trace_path(org, normalize(rot * d), forward, spread, rng);
    if (i == 0u) first = s;
    const vec3 demod = max(s.albedo, vec3(kPtMinDemodAlbedo));
    sum_d += finite_or_zero(s.direct / demod);
    sum_i += finite_or_zero(s.indirect / demod);
    sum_a += s.albedo;
    sum_l += finite_or_zero(s.direct + s.indirect);
  }
  const float inv = 1.0 / float(spp);
  vec3 dir_mean = sum_d * inv, ind_mean = sum_i * inv, alb_mean = sum_a * inv, rad_mean = sum_l * inv;
  if (accumulate) {
    // Running mean: every sample weighs the same.
    const float w = float(spp) / float(pc.accumulated_samples + spp);
    dir_mean = mix(out_direct[idx].rgb, dir_mean, w);
    ind_mean = mix(out_indirect[idx].rgb, ind_mean, w);
    alb_mean = mix(out_albedo[idx].rgb, alb_mean, w);
    rad_mean = mix(out_radiance[idx].rgb, rad_mean, w);
  }
  const float held = accumulate ? 1.0 : float(spp);  // samples in this mean (Phase I's count)
  out_direct[idx] = vec4(finite_or_zero(dir_mean), held);
  out_indirect[idx] = vec4(finite_or_zero(ind_mean), held);
  out_albedo[idx] = vec4(finite_or_zero(alb_mean), 1.0);
  out_radiance[idx] = vec4(finite_or_zero(rad_mean), 1.0);
  if (!accumulate) {
    out_normal_depth[idx] = vec4(finite_or_zero(first.normal), isinf(first.depth) || isnan(first.depth) ? 0.0 : first.depth);
    out_position_material[idx] = vec4(finite_or_zero(first.position), first.material);
  }
}
