// GLSL only: the counter-based random numbers and the BSDF (GGX with Smith masking and a
// multiple-scattering lobe over an energy-compensated Lambert base, glTF
// metallic-roughness) of the path tracer. The includer
// declares `textureBuffer ggx_albedo`, the table described with kPtGgxTableSize (pt_scene.h).
#ifndef FOVEA_SHADERS_PT_SAMPLING_H
#define FOVEA_SHADERS_PT_SAMPLING_H

const float kPtPi = 3.14159265358979;

// pcg4d (Jarzynski & Olano 2020, "Hash functions for GPU rendering", JCGT 9(3)).
uvec4 pt_pcg4d(uvec4 v) {
  v = v * 1664525u + 1013904223u;
  v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
  v ^= v >> 16u;
  v.x += v.y * v.w; v.y += v.z * v.x; v.z += v.x * v.y; v.w += v.y * v.z;
  return v;
}

// Counter-based: the stream is a pure function of (cell, frame, eye, sample), so the two
// eyes are decorrelated and every run reproduces bit for bit.
struct PtRng {
  uvec4 key;
  uint counter;
  uvec4 cache;
};

PtRng pt_rng(uint cell, uint frame, uint eye, uint sample_index) {
  PtRng r;
  r.key = uvec4(cell, frame, eye, sample_index);
  r.counter = 0u;
  return r;
}

float pt_rand(inout PtRng r) {
  if ((r.counter & 3u) == 0u) r.cache = pt_pcg4d(r.key ^ uvec4(0u, 0u, 0u, r.counter * 0x9E3779B9u) + uvec4(r.counter));
  const uint bits = r.cache[r.counter & 3u];
  r.counter++;
  return float(bits >> 8u) * (1.0 / 16777216.0);  // [0, 1)
}

float pt_luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
float pt_max3(vec3 v) { return max(v.x, max(v.y, v.z)); }

// Orthonormal basis around n (Duff et al. 2017).
void pt_basis(vec3 n, out vec3 t, out vec3 b) {
  const float s = n.z >= 0.0 ? 1.0 : -1.0;
  const float a = -1.0 / (s + n.z);
  const float c = n.x * n.y * a;
  t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}

struct PtBsdf {
  vec3 diffuse;  // base · (1 − metallic)
  vec3 f0;       // mix(specular, base, metallic)
  float alpha;   // GGX roughness² (≥ 0.0004)
};

float pt_ggx_d(float noh, float a2) {
  const float d = noh * noh * (a2 - 1.0) + 1.0;
  return a2 / (kPtPi * d * d);
}
// Smith Λ for GGX; G1 = 1/(1+Λ), height-correlated G2 = 1/(1+Λo+Λi) (Heitz 2014, Eq. 72, 99).
float pt_ggx_lambda(float cos_t, float a2) {
  const float c2 = cos_t * cos_t;
  return 0.5 * (sqrt(1.0 + a2 * (1.0 - c2) / max(c2, 1e-12)) - 1.0);
}
vec3 pt_fresnel(vec3 f0, float c) {
  const float m = clamp(1.0 - c, 0.0, 1.0);
  return f0 + (1.0 - f0) * (m * m * m * m * m);
}

// Table entry (A, B, A_avg, B_avg) at (μ, α), bilinear in (√μ, √α) between the nodes.
vec4 pt_ggx_albedo(float mu, float alpha) {
  const float n1 = float(kPtGgxTableSize - 1u);
  const vec2 p = sqrt(clamp(vec2(mu, alpha), 0.0, 1.0)) * n1;
  const uvec2 i0 = uvec2(min(p, vec2(n1 - 1.0)));
  const vec2 f = p - vec2(i0);
  const uint row = kPtGgxTableSize;
  const uint k = i0.y * row + i0.x;
  const int i = int(k), r = int(row);
  return mix(mix(texelFetch(ggx_albedo, i), texelFetch(ggx_albedo, i + 1), f.x),
             mix(texelFetch(ggx_albedo, i + r), texelFetch(ggx_albedo, i + r + 1), f.x), f.y);
}

// Multiple scattering of the specular layer (Kulla & Conty 2017, "Revisiting physically
// based shading at Imageworks"): with E1 = A + B the single-scattering albedo for F = 1,
//   f_ms = F_ms · (1 − E1(μo))(1 − E1(μi)) / (π(1 − E1_avg)),
//   F_ms = F_avg²·E1_avg / (1 − F_avg(1 − E1_avg)), F_avg = F0 + (1 − F0)/21 (Schlick's
// cosine-weighted mean), restores the energy masking removes: albedo F_ms(1 − E1(μo)), so a
// white metal (F0 = 1, F_ms = 1) reflects exactly 1. Returns F_ms.
vec3 pt_ms_scale(vec3 f0, float e1_avg) {
  const vec3 fa = f0 + (1.0 - f0) / 21.0;
  return fa * fa * e1_avg / (1.0 - fa * (1.0 - e1_avg));
}

// Albedo of the whole specular layer (single + multiple scattering) at μ from its table
// entry t, and the same for the cosine-weighted hemispherical mean.
vec3 pt_layer_albedo(vec3 f0, vec3 fms, vec4 t) { return f0 * t.x + t.y + fms * (1.0 - (t.x + t.y)); }
vec3 pt_layer_albedo_avg(vec3 f0, vec3 fms, vec4 t) { return f0 * t.z + t.w + fms * (1.0 - (t.z + t.w)); }

// Probability of sampling the GGX lobe (visible normals) rather than the cosine lobe, which
// serves the diffuse base and the multiple-scattering lobe; from the lobes' rough weights.
float pt_spec_prob(PtBsdf m, float cos_o) {
  if (pt_max3(m.f0) <= 0.0) return 0.0;
  const float es = pt_luminance(pt_fresnel(m.f0, cos_o));
  const vec4 t = pt_ggx_albedo(cos_o, m.alpha);
  const float ems = pt_luminance(pt_ms_scale(m.f0, t.z + t.w)) * (1.0 - (t.x + t.y));
  const float ed = pt_luminance(m.diffuse);
  // Metals: unclamped, so mirrors keep (almost) all samples on the GGX lobe.
  if (ed <= 0.0) return es / (es + ems);
  return clamp(es / (es + ed + ems), 0.1, 0.9);
}

// f·cos split into the diffuse and specular lobes, and the sampling pdf (solid angle).
void pt_bsdf_eval(PtBsdf m, vec3 n, vec3 wo, vec3 wi, out vec3 f_diff, out vec3 f_spec, out float pdf) {
  f_diff = vec3(0.0);
  f_spec = vec3(0.0);
  pdf = 0.0;
  const float ci = dot(n, wi), co = dot(n, wo);
  if (ci <= 0.0 || co <= 0.0) return;
  const float ps = pt_spec_prob(m, co);
  f_diff = m.diffuse * (ci / kPtPi);
  pdf = (1.0 - ps) * ci / kPtPi;
  if (ps > 0.0) {
    const vec3 h = normalize(wo + wi);
    const float noh = max(dot(n, h), 0.0), hoo = max(dot(wo, h), 1e-8);
    const float a2 = m.alpha * m.alpha;
    const float D = pt_ggx_d(noh, a2);
    const float lo = pt_ggx_lambda(co, a2), li = pt_ggx_lambda(ci, a2);
    const float G2 = 1.0 / (1.0 + lo + li), G1 = 1.0 / (1.0 + lo);
    // D·G2·F / (4 cos_i cos_o), times cos_i (Walter et al. 2007, Eq. 20).
    f_spec = pt_fresnel(m.f0, hoo) * (D * G2 / (4.0 * co));
    // Visible-normal sampling pdf of wi: G1(wo)·D / (4 cos_o) (Heitz 2018, Eq. 17 with the Jacobian).
    pdf += ps * G1 * D / (4.0 * co);
    const vec4 to = pt_ggx_albedo(co, m.alpha), ti = pt_ggx_albedo(ci, m.alpha);
    const float e1_avg = to.z + to.w;
    const vec3 fms = pt_ms_scale(m.f0, e1_avg);
    f_spec += fms * ((1.0 - (to.x + to.y)) * (1.0 - (ti.x + ti.y)) * ci / (kPtPi * max(1.0 - e1_avg, 1e-4)));
    // Energy-compensated layering (Kelemen & Szirmay-Kalos 2001; Kulla & Conty 2017):
    // the diffuse base receives what the specular layer E does not reflect, reciprocally,
    // f_d = ρ/π · (1 − E(μo))(1 − E(μi)) / (1 − E_avg); its albedo is then ρ(1 − E(μo)), so
    // E(μo) + ρ(1 − E(μo)) ≤ 1 for every ρ ≤ 1 (the plain sum reached 1.33 at grazing).
    const vec3 eo = pt_layer_albedo(m.f0, fms, to), ei = pt_layer_albedo(m.f0, fms, ti);
    const vec3 eavg = pt_layer_albedo_avg(m.f0, fms, to);
    f_diff *= clamp((1.0 - eo) * (1.0 - ei) / max(1.0 - eavg, vec3(1e-4)), 0.0, 1e4);
  }
}

// GGX visible normals (Heitz 2018, "Sampling the GGX distribution of visible normals").
vec3 pt_sample_vndf(vec3 wo_local, float alpha, float u1, float u2) {
  const vec3 vh = normalize(vec3(alpha * wo_local.x, alpha * wo_local.y, wo_local.z));
  const float lensq = vh.x * vh.x + vh.y * vh.y;
  const vec3 T1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
  const vec3 T2 = cross(vh, T1);
  const float r = sqrt(u1), phi = 2.0 * kPtPi * u2;
  const float t1 = r * cos(phi);
  float t2 = r * sin(phi);
  const float s = 0.5 * (1.0 + vh.z);
  t2 = (1.0 - s) * sqrt(max(0.0, 1.0 - t1 * t1)) + s * t2;
  const vec3 nh = t1 * T1 + t2 * T2 + sqrt(max(0.0, 1.0 - t1 * t1 - t2 * t2)) * vh;
  return normalize(vec3(alpha * nh.x, alpha * nh.y, max(0.0, nh.z)));
}

// Samples wi from the lobe mixture; false when no valid direction was produced.
bool pt_bsdf_sample(PtBsdf m, vec3 n, vec3 wo, vec3 u, out vec3 wi) {
  const float co = dot(n, wo);
  if (co <= 0.0) return false;
  vec3 t, b;
  pt_basis(n, t, b);
  if (u.x < pt_spec_prob(m, co)) {
    const vec3 wl = vec3(dot(wo, t), dot(wo, b), co);
    const vec3 hl = pt_sample_vndf(wl, m.alpha, u.y, u.z);
    const vec3 h = hl.x * t + hl.y * b + hl.z * n;
    wi = reflect(-wo, h);
  } else {
    const float r = sqrt(u.y), phi = 2.0 * kPtPi * u.z;  // cosine-weighted hemisphere
    wi = r * cos(phi) * t + r * sin(phi) * b + sqrt(max(0.0, 1.0 - u.y)) * n;
  }
  return dot(n, wi) > 0.0;
}

float pt_power_heuristic(float a, float b) {
  const float a2 = a * a, b2 = b * b;
  return a2 + b2 > 0.0 ? a2 / (a2 + b2) : 0.0;
}

#endif
