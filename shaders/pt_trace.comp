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
// pt_shading(), pt_material() (pt_surface.h) and pt_light() below.
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

PtLight pt_light(uint i) {
  const vec4 a = texelFetch(lights, int(i));
  return PtLight(floatBitsToUint(a.x), a.y, a.z, a.w);
}

#include "fovea/shaders/pt_surface.h"

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
  // The primary ray's cone (PathConfig::texture_cone) in cells of the cell's angular size.
  const float spread = pt_cone_spread(pc.texture_cone * g.footprint * sqrt(pc.pixel_tx * pc.pixel_ty), dv);
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
