#version 460
// BMFR Phase II (Koskela et al. 2019 §3.3–3.4) on one 32×32 block of the grid per
// workgroup: features T = [1, n, w, w²] (M = 10, Eq. 8) with the world position w scaled per
// block to [−1, 1] before squaring (so w² cannot overflow whatever the scene's units),
// uniform ±ε noise on the non-constant features (Eq. 7), Householder QR of [T + N | z_r z_g z_b]
// keeping only R (Q is never formed), back substitution R α = r (Eq. 5) per channel and the
// weighted sum with the noise-free features (Eq. 6). Cells without a surface sample
// (clipped, off-screen, padding, sky) and emitters are zero rows: masked out of the regression
// (the sky and emitters keep their accumulated input).
//
// Workgroup: 256 invocations own 4 rows (cells) each, kept in registers for the whole QR.
// Each reduction sums 4 rows per invocation, then the subgroup (8 lanes on lavapipe), then
// the subgroups' partials from shared memory (4·8·32 = 1024). One reduction round per
// Householder column: ‖x‖² and every x·a_j at once, since v = x − αe_k gives
// v·a_j = x·a_j − α·a_j[k].
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

layout(local_size_x = 256) in;

#include "fovea/shaders/hash.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = 0) readonly buffer Pos { vec4 vpos[]; };
layout(std430, binding = 1) readonly buffer Nrm { vec4 vnrm[]; };
layout(std430, binding = 2) readonly buffer Z { vec4 z[]; };
layout(std430, binding = 3) writeonly buffer Fitted { vec4 fitted[]; };

layout(push_constant) uniform Push { ReconBmfrPush pc; };

const uint kRows = 4u;        // rows per invocation (1024 / 256)
const uint kM = 10u;          // features
const uint kCols = 13u;       // features + 3 colour channels
const uint kVals = 14u;       // reduction width
const uint kMaxSubgroups = 64u;

shared float s_partial[kMaxSubgroups][kVals];
shared float s_result[kVals];
shared float s_rowk[2][kCols];
shared float s_r[kM][kCols];
shared float s_coef[3][kM];

float A[kRows][kCols];

// Sum (op 0) or max (op 1) of vals over the workgroup; every invocation gets the result.
void reduce(inout float vals[kVals], uint n, uint op) {
  for (uint j = 0u; j < n; ++j) {
    float r = op == 0u ? subgroupAdd(vals[j]) : subgroupMax(vals[j]);
    if (subgroupElect()) s_partial[gl_SubgroupID][j] = r;
  }
  barrier();
  uint t = gl_LocalInvocationIndex;
  if (t < n) {
    float acc = s_partial[0][t];
    for (uint g = 1u; g < gl_NumSubgroups; ++g) acc = op == 0u ? acc + s_partial[g][t] : max(acc, s_partial[g][t]);
    s_result[t] = acc;
  }
  barrier();
  for (uint j = 0u; j < n; ++j) vals[j] = s_result[j];
}

ivec2 cell_of(uint row) {
  uint block = gl_WorkGroupID.x;
  ivec2 origin = ivec2(int(block % pc.blocks_x) * 32 - pc.offset_x, int(block / pc.blocks_x) * 32 - pc.offset_y);
  return origin + ivec2(int(row & 31u), int(row >> 5));
}

bool inside(ivec2 c) { return c.x >= 0 && c.y >= 0 && c.x < int(pc.padded_columns) && c.y < int(pc.padded_rows); }

void main() {
  uint tid = gl_LocalInvocationIndex;
  bool valid[kRows];
  vec3 wpos[kRows];
  float vals[kVals];

  // Per-block position range: max of (w, −w) over valid rows; and the number of valid rows.
  for (uint j = 0u; j < kVals; ++j) vals[j] = -3.0e38;
  float count = 0.0;
  for (uint q = 0u; q < kRows; ++q) {
    ivec2 c = cell_of(tid + q * 256u);
    valid[q] = false;
    wpos[q] = vec3(0.0);
    if (!inside(c)) continue;
    vec4 p = vpos[uint(c.y) * pc.padded_columns + uint(c.x)];
    if (p.w < 0.0) continue;  // sky, emitter or no sample
    valid[q] = true;
    wpos[q] = p.xyz;
    count += 1.0;
    for (uint a = 0u; a < 3u; ++a) {
      vals[a] = max(vals[a], p[a]);
      vals[3u + a] = max(vals[3u + a], -p[a]);
    }
  }
  reduce(vals, 6u, 1u);
  vec3 wmax = vec3(vals[0], vals[1], vals[2]), wmin = -vec3(vals[3], vals[4], vals[5]);
  for (uint j = 0u; j < kVals; ++j) vals[j] = 0.0;
  vals[0] = count;
  reduce(vals, 1u, 0u);
  float valid_rows = vals[0];

  // Blocks without a surface sample only pass sky through (uniform branch: no barrier inside).
  if (valid_rows < 0.5) {
    for (uint q = 0u; q < kRows; ++q) {
      ivec2 c = cell_of(tid + q * 256u);
      if (!inside(c)) continue;
      uint i = uint(c.y) * pc.padded_columns + uint(c.x);
      fitted[i] = rg_no_sample(vpos[i].w) ? vec4(0.0) : z[i];
    }
    return;
  }

  vec3 mid = 0.5 * (wmax + wmin);
  vec3 half_range = 0.5 * (wmax - wmin);
  vec3 inv_half = vec3(half_range.x > 1e-6 ? 1.0 / half_range.x : 0.0, half_range.y > 1e-6 ? 1.0 / half_range.y : 0.0,
                       half_range.z > 1e-6 ? 1.0 / half_range.z : 0.0);
  vec3 feat_n[kRows];
  for (uint q = 0u; q < kRows; ++q) {
    uint row = tid + q * 256u;
    for (uint j = 0u; j < kCols; ++j) A[q][j] = 0.0;
    feat_n[q] = vec3(0.0);
    if (!valid[q]) continue;
    ivec2 c = cell_of(row);
    uint i = uint(c.y) * pc.padded_columns + uint(c.x);
    vec3 n = vnrm[i].xyz;
    vec3 w = clamp((wpos[q] - mid) * inv_half, -1.0, 1.0);
    feat_n[q] = n;
    vec3 zz = z[i].rgb;
    float t[kCols] = float[kCols](1.0, n.x, n.y, n.z, w.x, w.y, w.z, w.x * w.x, w.y * w.y, w.z * w.z, zz.r, zz.g, zz.b);
    // Eq. 7: zero-mean uniform noise on the non-constant features, keyed by block, row, feature, frame.
    for (uint j = 0u; j < kCols; ++j) {
      float noise = 0.0;
      if (j >= 1u && j < kM)
        noise = pc.noise * (2.0 * hash_to_unit(hash3(gl_WorkGroupID.x * 1024u + row, j, pc.frame)) - 1.0);
      A[q][j] = t[j] + noise;
    }
  }

  // Householder QR, column by column.
  for (uint k = 0u; k < kM; ++k) {
    for (uint j = 0u; j < kVals; ++j) vals[j] = 0.0;
    for (uint q = 0u; q < kRows; ++q) {
      uint row = tid + q * 256u;
      if (row < k) continue;
      float x = A[q][k];
      for (uint j = k; j < kCols; ++j) vals[j] += x * A[q][j];
      if (row == k)
        for (uint j = 0u; j < kCols; ++j) s_rowk[k & 1u][j] = A[q][j];
    }
    reduce(vals, kCols, 0u);
    float xk = s_rowk[k & 1u][k];
    float norm = sqrt(max(vals[k], 0.0));
    float alpha = xk > 0.0 ? -norm : norm;
    float vtv = 2.0 * (vals[k] - alpha * xk);
    float beta[kCols];
    for (uint j = 0u; j < kCols; ++j)
      beta[j] = (j > k && vtv > 1e-30) ? 2.0 * (vals[j] - alpha * s_rowk[k & 1u][j]) / vtv : 0.0;
    if (tid == 0u) {
      for (uint j = 0u; j < kCols; ++j) s_r[k][j] = j < k ? 0.0 : (j == k ? (vtv > 1e-30 ? alpha : xk) : s_rowk[k & 1u][j] - beta[j] * (xk - alpha));
    }
    for (uint q = 0u; q < kRows; ++q) {
      uint row = tid + q * 256u;
      if (row < k) continue;
      float v = row == k ? xk - alpha : A[q][k];
      for (uint j = k + 1u; j < kCols; ++j) A[q][j] -= beta[j] * v;
    }
  }
  barrier();

  // Back substitution (Eq. 5), one invocation per channel. Near-zero pivots (dependent
  // features the noise did not lift) get a zero coefficient instead of a division.
  if (tid < 3u) {
    float diag_max = 0.0;
    for (uint k = 0u; k < kM; ++k) diag_max = max(diag_max, abs(s_r[k][k]));
    for (int k = int(kM) - 1; k >= 0; --k) {
      float acc = s_r[k][kM + tid];
      for (uint j = uint(k) + 1u; j < kM; ++j) acc -= s_r[k][j] * s_coef[tid][j];
      float d = s_r[k][k];
      float a = abs(d) > 1e-5 * diag_max && abs(d) > 1e-12 ? acc / d : 0.0;
      s_coef[tid][k] = (isnan(a) || isinf(a)) ? 0.0 : a;
    }
  }
  barrier();

  // Weighted sum with the noise-free (scaled) features (Eq. 6); negative fits clamp to 0.
  for (uint q = 0u; q < kRows; ++q) {
    ivec2 c = cell_of(tid + q * 256u);
    if (!inside(c)) continue;
    uint i = uint(c.y) * pc.padded_columns + uint(c.x);
    if (!valid[q]) {
      fitted[i] = rg_no_sample(vpos[i].w) ? vec4(0.0) : z[i];
      continue;
    }
    vec3 n = feat_n[q];
    vec3 w = clamp((wpos[q] - mid) * inv_half, -1.0, 1.0);
    float t[kM] = float[kM](1.0, n.x, n.y, n.z, w.x, w.y, w.z, w.x * w.x, w.y * w.y, w.z * w.z);
    vec3 y = vec3(0.0);
    for (uint m = 0u; m < kM; ++m) y += vec3(s_coef[0][m], s_coef[1][m], s_coef[2][m]) * t[m];
    y = clamp(y, vec3(0.0), vec3(1e9));
    fitted[i] = vec4(isnan(y.r) || isnan(y.g) || isnan(y.b) ? vec3(0.0) : y, 1.0);
  }
}
