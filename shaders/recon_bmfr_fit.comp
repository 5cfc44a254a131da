#version 460
// BMFR Phase II (Koskela et al. 2019 §3.3–3.4) on one 32×32 block of the grid per
// workgroup: features T = [1, n, w, w²] (M = 10, Eq. 8) with the world position w scaled per
// block to [−1, 1] before squaring (so w² cannot overflow whatever the scene's units),
// uniform ±ε noise on the non-constant features (Eq. 7), Householder QR of [T + N | z_r z_g z_b]
// keeping only R (Q is never formed), back substitution R α = r (Eq. 5) per channel and the
// weighted sum with the noise-free features (Eq. 6). Cells without a surface sample
// (clipped, off-screen, padding, sky), emitters, surfaces without a diffuse lobe (metals) and
// cells straddling a surface edge are zero rows: masked out of the regression, they keep
// their accumulated input. A metal's indirect diffuse is zero by construction; fitted with
// its block's diffuse neighbours it took their light (docs/reconstruction.md, glossy-spheres).
//
// Workgroup: kGroup invocations (default 256) own 1024/kGroup rows (cells) each, kept in
// registers for the whole QR; every loop over rows and columns is unrolled so no private
// array is indexed dynamically. One reduction round per Householder column: ‖x‖² and every
// x·a_j at once, since v = x − αe_k gives v·a_j = x·a_j − α·a_j[k]. Measured alternatives:
// docs/reconstruction.md.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

layout(local_size_x_id = 0) in;
layout(constant_id = 0) const uint kGroup = 256u;  // invocations per block (divides 1024)
layout(constant_id = 1) const bool kFp16 = false;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/hash.h"
#include "fovea/shaders/recon_grid.h"
#include "fovea/shaders/pt_scene.h"

layout(std430, binding = RECON_BMFR_POS) readonly buffer Pos { vec4 vpos[]; };
layout(std430, binding = RECON_BMFR_NRM) readonly buffer Nrm { vec4 vnrm[]; };
layout(std430, binding = RECON_BMFR_Z) readonly buffer Z { vec4 z[]; };
layout(std430, binding = RECON_BMFR_FITTED) writeonly buffer Fitted { vec4 fitted[]; };
layout(std430, binding = RECON_BMFR_COLUMNS) readonly buffer Columns { GridColumn tables[]; };
layout(std430, binding = RECON_BMFR_MATERIALS) readonly buffer Materials { PtMaterial materials[]; };
layout(std430, binding = RECON_BMFR_EXCESS) writeonly buffer Excess { vec4 excess[]; };

layout(push_constant) uniform Push { ReconBmfrPush pc; };

#include "fovea/shaders/recon_map.h"

const uint kRows = 1024u / kGroup;  // rows per invocation
const uint kM = 10u;          // features
const uint kCols = 13u;       // features + 3 colour channels
const uint kVals = 14u;       // reduction width
const float kOutlier = 8.0;   // inputs above this multiple of their block's mean are outliers

shared float s_partial[kVals][kGroup];
shared float s_result[kVals];
shared float s_rowk[2][kCols];
shared float s_r[kM][kCols];
shared float s_coef[3][kM];

// The block's rows of [T + N | z], fp32 or fp16 pairs (kFp16); the unused one is dead code.
float A[kRows][kCols];
uint A16[kRows][(kCols + 1u) / 2u];

float a_get(uint q, uint j) { return kFp16 ? unpackHalf2x16(A16[q][j >> 1u])[j & 1u] : A[q][j]; }

void a_set(uint q, uint j, float v) {
  if (kFp16) {
    vec2 h = unpackHalf2x16(A16[q][j >> 1u]);
    h[j & 1u] = v;
    A16[q][j >> 1u] = packHalf2x16(h);
  } else {
    A[q][j] = v;
  }
}

// Max (bit j of max_mask set) or sum (clear) of each of vals[0..n) over the workgroup; every
// invocation gets the results. Each invocation stores its values, then invocation j folds
// value j over the group serially: on lavapipe this beats subgroup reductions (which loop
// over the lanes of every subgroup for every value) several times over.
void reduce(inout float vals[kVals], uint n, uint max_mask) {
  uint tid = gl_LocalInvocationIndex;
  [[unroll]] for (uint j = 0u; j < n; ++j) s_partial[j][tid] = vals[j];
  barrier();
  if (tid < n) {
    bool is_max = ((max_mask >> tid) & 1u) != 0u;
    float acc = s_partial[tid][0];
    for (uint g = 1u; g < kGroup; ++g) acc = is_max ? max(acc, s_partial[tid][g]) : acc + s_partial[tid][g];
    s_result[tid] = acc;
  }
  barrier();
  [[unroll]] for (uint j = 0u; j < n; ++j) vals[j] = s_result[j];
}

// Householder step on column k of the block (rows >= k): one reduction gives ‖x‖² and
// every x·a_j; v = x − αe_k, so v·a_j = x·a_j − α a_j[k]; a_j −= 2(v·a_j)/(v·v) v. Row k of
// R goes to s_r.
void householder_column(const uint k) {
  uint tid = gl_LocalInvocationIndex;
  float vals[kVals];
  [[unroll]] for (uint j = 0u; j < kVals; ++j) vals[j] = 0.0;
  [[unroll]] for (uint q = 0u; q < kRows; ++q) {
    uint row = tid + q * kGroup;
    if (row >= k) {
      float x = a_get(q, k);
      [[unroll]] for (uint j = k; j < kCols; ++j) vals[j] += x * a_get(q, j);
      if (row == k)
        [[unroll]] for (uint j = 0u; j < kCols; ++j) s_rowk[k & 1u][j] = a_get(q, j);
    }
  }
  reduce(vals, kCols, 0u);  // sums
  float xk = s_rowk[k & 1u][k];
  float norm = sqrt(max(vals[k], 0.0));
  float alpha = xk > 0.0 ? -norm : norm;
  float vtv = 2.0 * (vals[k] - alpha * xk);
  float beta[kCols];
  [[unroll]] for (uint j = 0u; j < kCols; ++j)
    beta[j] = (j > k && vtv > 1e-30) ? 2.0 * (vals[j] - alpha * s_rowk[k & 1u][j]) / vtv : 0.0;
  if (tid == 0u) {
    [[unroll]] for (uint j = 0u; j < kCols; ++j)
      s_r[k][j] = j < k ? 0.0 : (j == k ? (vtv > 1e-30 ? alpha : xk) : s_rowk[k & 1u][j] - beta[j] * (xk - alpha));
  }
  [[unroll]] for (uint q = 0u; q < kRows; ++q) {
    uint row = tid + q * kGroup;
    if (row >= k) {
      float v = row == k ? xk - alpha : a_get(q, k);
      [[unroll]] for (uint j = k + 1u; j < kCols; ++j) a_set(q, j, a_get(q, j) - beta[j] * v);
    }
  }
}

// The grid cell of one of the block's rows. On polar grids φ is cyclic: the displaced block
// rows v ∈ [−offset_y, padded_rows − offset_y) of column x take its rows modulo their count
// R (v < R − offset_y), so no block boundary stays at φ = 0; v beyond covers the clipped
// rows [R, padded_rows) once, so every cell still belongs to exactly one block. A column
// packed to its visible arc cycles over all its padded rows instead: its clipped rows
// [R, padded_rows) lie between the arc's two ends.
ivec2 cell_of(uint row) {
  uint block = gl_WorkGroupID.x;
  int x = int(block % pc.blocks_x) * 32 - pc.offset_x + int(row & 31u);
  int v = int(block / pc.blocks_x) * 32 - pc.offset_y + int(row >> 5);
  if (pc.columns == 0u) return ivec2(x, v);
  int rows = x >= 0 && x < int(pc.columns) ? int(tables[x].rows) : 0;
  if (rows > 0 && tables[x].phi_gap > 0.0) rows = int(pc.padded_rows);  // a packed arc: its ends do not meet
  return ivec2(x, v < rows - pc.offset_y ? (v % rows + rows) % rows : v + pc.offset_y);
}

// Material code (vpos.w ≥ 0) of a surface with a diffuse lobe (pt_trace.comp: diffuse
// albedo = base × (1 − metallic)); codes beyond the table count as diffuse.
bool has_diffuse(float code) {
  uint m = uint(code);
  if (m >= uint(materials.length())) return true;
  PtMaterial mat = materials[m];
  return mat.metallic < 1.0 && (mat.texture >= 0 || max(max(mat.base_r, mat.base_g), mat.base_b) > 0.0);
}

// Whether cell i's area straddles a surface edge: a 3×3 grid neighbour (this frame's samples)
// holds a surface the history test (rg_tap_valid) would not take for i's own. With sub-cell
// jitter Phase I keeps the history of such a cell over the samples of both sides (its area
// mean: recon_accumulate.comp, seen_near), and that mix is no function of the features of the
// side the sample hit now: fitted with its block it biased the fit at silhouettes, and the
// fit put the surface's full light where the cell's area is partly background (cornell,
// 58–60°, docs/reconstruction.md). An edge inside the cell's area always has a neighbour's
// sample on its other side, since all cells share the frame's jitter.
bool straddles(uint i) {
  ReconGrid m;  // this frame's grid as recon_map.h reads it (the column table at offset 0)
  m.g.family = pc.columns > 0u ? kFamilyAngularPolar : kFamilyCartesian;
  m.g.columns = pc.columns > 0u ? pc.columns : pc.padded_columns;
  m.g.rows = pc.padded_rows;
  m.g.padded_columns = pc.padded_columns;
  m.table_offset = 0u;
  vec4 here = vpos[i], nd = vnrm[i];
  for (int dc = -1; dc <= 1; ++dc)
    for (int dr = -1; dr <= 1; ++dr) {
      uint k;
      if ((dc != 0 || dr != 0) && rg_neighbour(m, i, dc, dr, k) && !rg_no_sample(vpos[k].w) &&
          !rg_tap_valid(here, nd.xyz, nd.w, vpos[k], vnrm[k].xyz))
        return true;
    }
  return false;
}

bool inside(ivec2 c) { return c.x >= 0 && c.y >= 0 && c.x < int(pc.padded_columns) && c.y < int(pc.padded_rows); }

void main() {
  uint tid = gl_LocalInvocationIndex;
  bool valid[kRows];
  vec3 wpos[kRows], zin[kRows];
  float vals[kVals];

  // One reduction over the valid rows: maxima of the position range (max of w and −w), of
  // whether any row is valid and of the input; sums of the input (rgb) and of the rows.
  [[unroll]] for (uint j = 0u; j < kVals; ++j) vals[j] = j < 8u ? -3.0e38 : 0.0;
  [[unroll]] for (uint q = 0u; q < kRows; ++q) {
    ivec2 c = cell_of(tid + q * kGroup);
    valid[q] = false;
    wpos[q] = vec3(0.0);
    zin[q] = vec3(0.0);
    if (!inside(c)) continue;
    uint i = uint(c.y) * pc.padded_columns + uint(c.x);
    vec4 p = vpos[i];
    if (p.w < 0.0 || !has_diffuse(p.w) || straddles(i)) continue;  // sky, emitter, no sample, metal, edge
    valid[q] = true;
    wpos[q] = p.xyz;
    zin[q] = z[i].rgb;
    [[unroll]] for (uint a = 0u; a < 3u; ++a) {
      vals[a] = max(vals[a], p[a]);
      vals[3u + a] = max(vals[3u + a], -p[a]);
    }
    vals[6] = 1.0;
    vals[7] = max(vals[7], max(max(zin[q].r, zin[q].g), zin[q].b));
    [[unroll]] for (uint a = 0u; a < 3u; ++a) vals[8u + a] += zin[q][a];
    vals[11] += 1.0;
  }
  reduce(vals, 12u, 0xFFu);
  vec3 wmax = vec3(vals[0], vals[1], vals[2]), wmin = -vec3(vals[3], vals[4], vals[5]);
  // Outliers stay out of the fit (deviation from Koskela): the regression sees the input
  // clamped to kOutlier × its block mean per channel, and each cell's excess goes to the
  // excess buffer, added back after Phase III (recon_post.comp): no energy is lost and none
  // is spread. A firefly (e.g. a caustic: floor → glossy sphere → light, 300× the mean at
  // 1 spp) otherwise lifts its whole block (docs/reconstruction.md, glossy-spheres).
  vec3 bound = kOutlier * vec3(vals[8], vals[9], vals[10]) / max(vals[11], 1.0);
  // z enters the regression divided by its (clamped) block maximum (the fit is linear in z,
  // so the fitted values scale back): every column then stays within fp16 range.
  float zmax = min(vals[7], max(max(bound.r, bound.g), bound.b));
  zmax = zmax > 0.0 ? zmax : 1.0;

  // Blocks without a surface sample only pass sky through (uniform branch: no barrier inside).
  if (vals[6] < 0.5) {
    [[unroll]] for (uint q = 0u; q < kRows; ++q) {
      ivec2 c = cell_of(tid + q * kGroup);
      if (!inside(c)) continue;
      uint i = uint(c.y) * pc.padded_columns + uint(c.x);
      fitted[i] = rg_no_sample(vpos[i].w) ? vec4(0.0) : z[i];
      excess[i] = vec4(0.0);
    }
    return;
  }

  vec3 mid = 0.5 * (wmax + wmin);
  vec3 half_range = 0.5 * (wmax - wmin);
  vec3 inv_half = vec3(half_range.x > 1e-6 ? 1.0 / half_range.x : 0.0, half_range.y > 1e-6 ? 1.0 / half_range.y : 0.0,
                       half_range.z > 1e-6 ? 1.0 / half_range.z : 0.0);
  vec3 feat_n[kRows];
  [[unroll]] for (uint q = 0u; q < kRows; ++q) {
    uint row = tid + q * kGroup;
    [[unroll]] for (uint j = 0u; j < kCols; ++j) a_set(q, j, 0.0);
    feat_n[q] = vec3(0.0);
    if (!valid[q]) continue;
    ivec2 c = cell_of(row);
    uint i = uint(c.y) * pc.padded_columns + uint(c.x);
    vec3 n = vnrm[i].xyz;
    vec3 w = clamp((wpos[q] - mid) * inv_half, -1.0, 1.0);
    feat_n[q] = n;
    vec3 zz = min(zin[q], bound) / zmax;
    float t[kCols] = float[kCols](1.0, n.x, n.y, n.z, w.x, w.y, w.z, w.x * w.x, w.y * w.y, w.z * w.z, zz.r, zz.g, zz.b);
    // Eq. 7: zero-mean uniform noise on the non-constant features, keyed by block, row, feature, frame.
    [[unroll]] for (uint j = 0u; j < kCols; ++j) {
      float noise = 0.0;
      if (j >= 1u && j < kM)
        noise = pc.noise * (2.0 * hash_to_unit(hash3(gl_WorkGroupID.x * 1024u + row, j, pc.frame)) - 1.0);
      a_set(q, j, t[j] + noise);
    }
  }

  // Householder QR, one call per column: after inlining every index into A is a constant
  // (llvmpipe turns dynamically indexed private arrays into per-lane memory traffic).
  householder_column(0u);
  householder_column(1u);
  householder_column(2u);
  householder_column(3u);
  householder_column(4u);
  householder_column(5u);
  householder_column(6u);
  householder_column(7u);
  householder_column(8u);
  householder_column(9u);
  barrier();

  // Back substitution (Eq. 5), one invocation per channel. Near-zero pivots (dependent
  // features the noise did not lift) get a zero coefficient instead of a division.
  if (tid < 3u) {
    float diag_max = 0.0;
    [[unroll]] for (uint k = 0u; k < kM; ++k) diag_max = max(diag_max, abs(s_r[k][k]));
    [[unroll]] for (int k = int(kM) - 1; k >= 0; --k) {
      float acc = s_r[k][kM + tid];
      [[unroll]] for (uint j = uint(k) + 1u; j < kM; ++j) acc -= s_r[k][j] * s_coef[tid][j];
      float d = s_r[k][k];
      float a = abs(d) > 1e-5 * diag_max && abs(d) > 1e-12 ? acc / d : 0.0;
      s_coef[tid][k] = (isnan(a) || isinf(a)) ? 0.0 : a;
    }
  }
  barrier();

  // Weighted sum with the noise-free (scaled) features (Eq. 6); negative fits clamp to 0.
  [[unroll]] for (uint q = 0u; q < kRows; ++q) {
    ivec2 c = cell_of(tid + q * kGroup);
    if (!inside(c)) continue;
    uint i = uint(c.y) * pc.padded_columns + uint(c.x);
    excess[i] = vec4(valid[q] ? max(zin[q] - bound, vec3(0.0)) : vec3(0.0), 0.0);
    if (!valid[q]) {
      fitted[i] = rg_no_sample(vpos[i].w) ? vec4(0.0) : z[i];
      continue;
    }
    vec3 n = feat_n[q];
    vec3 w = clamp((wpos[q] - mid) * inv_half, -1.0, 1.0);
    float t[kM] = float[kM](1.0, n.x, n.y, n.z, w.x, w.y, w.z, w.x * w.x, w.y * w.y, w.z * w.z);
    vec3 y = vec3(0.0);
    [[unroll]] for (uint m = 0u; m < kM; ++m) y += vec3(s_coef[0][m], s_coef[1][m], s_coef[2][m]) * t[m];
    y = clamp(y * zmax, vec3(0.0), vec3(1e9));
    // .w: the samples behind the input (its count), Phase III's weight for this fit.
    fitted[i] = vec4(isnan(y.r) || isnan(y.g) || isnan(y.b) ? vec3(0.0) : y, z[i].w);
  }
}
