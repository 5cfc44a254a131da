#version 460
// BMFR Phase II (Koskela et al. 2019 §3.3–3.4) on one 32×32 block of the grid per
// workgroup: features T = [1, n, w, w²] (M = 10, Eq. 8) with the world position w scaled per
// block to [−1, 1] before squaring (so w² cannot overflow whatever the scene's units),
// uniform ±ε noise on the non-constant features (Eq. 7), the least-squares fit of
// z_r z_g z_b on T + N (Eq. 5) and the weighted sum with the noise-free features (Eq. 6).
// Cells without a surface sample (clipped, off-screen, padding, sky), emitters, surfaces
// without a diffuse lobe (metals) and cells straddling a surface edge (flagged by the stereo
// gather, recon_share.comp) are zero rows: masked
// out of the regression, they keep their accumulated input. A metal's indirect diffuse is
// zero by construction; fitted with its block's diffuse neighbours it took their light
// (docs/reconstruction.md, glossy-spheres).
//
// The R of the QR of [T + N | z] (Eq. 5's triangular system) comes from the Cholesky
// factorisation of the Gram matrix [T + N | z]ᵀ[T + N | z] (deviation from the paper's
// Householder QR, same R up to row signs): one reduction of its 85 upper entries instead of
// one per Householder column, each invocation summing its rows' outer products as it
// streams them; on lavapipe the QR's ten reduction rounds and its rows held in registers
// across them were the chain's largest cost (docs/reconstruction.md, "Workgroup design").
// The normal equations square the condition number, so every non-constant feature is
// shifted by its block mean first (the constant feature spans any shift: the fit is the
// same): without the shift a planar block's n (constant up to ε) would lose the ε that
// regularises it to cancellation in fp32. Pivots whose column lies within 10⁻⁵ (squared
// sine) of the previous columns' span are dropped (zero coefficient).
//
// Workgroup: kGroup invocations loop over 1024/kGroup rows each; a row's grid cell and
// validity are kept in shared memory. The schedule follows the device
// (reconstruct::bmfr_schedule): on a CPU device 8 (one 8-wide SIMD row of lavapipe) with a
// serial fold for the reductions; on a GPU 256, whose reductions (FOVEA_SUBGROUP_REDUCE, this
// file's variant for devices with subgroup arithmetic) add within each subgroup first, so the
// serial fold runs over the subgroups' partial sums, not over every invocation.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers
#extension GL_EXT_control_flow_attributes : require
#ifdef FOVEA_SUBGROUP_REDUCE
#extension GL_KHR_shader_subgroup_arithmetic : require
#endif

layout(local_size_x_id = 0) in;
layout(constant_id = 0) const uint kGroup = 8u;  // invocations per block (divides 1024)
layout(constant_id = 1) const bool kFp16 = false;   // features rounded to fp16 (the paper's storage)

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/hash.h"
#include "fovea/shaders/recon_grid.h"
#include "fovea/shaders/pt_scene.h"

layout(binding = RECON_BMFR_POS) uniform textureBuffer vpos;
layout(binding = RECON_BMFR_NRM) uniform textureBuffer vnrm;
layout(binding = RECON_BMFR_Z) uniform textureBuffer z;
layout(std430, binding = RECON_BMFR_FITTED) writeonly buffer Fitted { vec4 fitted[]; };
layout(std430, binding = RECON_BMFR_COLUMNS) readonly buffer Columns { GridColumn tables[]; };
layout(std430, binding = RECON_BMFR_MATERIALS) readonly buffer Materials { PtMaterial materials[]; };
layout(std430, binding = RECON_BMFR_EXCESS) writeonly buffer Excess { vec4 excess[]; };
layout(binding = RECON_BMFR_EDGE) uniform utextureBuffer edge;  // 1: on a surface edge

layout(push_constant) uniform Push { ReconBmfrPush pc; };

const uint kRows = 1024u / kGroup;  // rows per invocation
const uint kM = 10u;                // features
const uint kCols = 13u;             // features + 3 colour channels
const uint kGram = 85u;             // Gram entries (k, j), k < kM, k <= j < kCols
// Values reduced per round: the partial sums of a round fit in 24 KB of shared memory.
const uint kChunk = kGroup * kGram <= 6144u ? kGram : 6144u / kGroup;
const float kOutlier = 8.0;         // inputs above this multiple of their block's mean are outliers
const float kPivot = 1e-5;          // smallest squared sine between a column and the span before it
const uint kOutside = 0xFFFFFFFFu;  // s_cell: the row's cell is off the grid
const uint kMasked = 0x80000000u;   // s_cell: a zero row (no sample, sky, emitter, no diffuse lobe)

// Row k and column j of each Gram entry, so the row update is one flat unrolled loop: with
// nested k, j loops llvmpipe left the 85 sums partly dynamically indexed (3× the fit's time).
const uint kGramK[kGram] = uint[kGram](
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2,
    2, 2, 2, 2, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 5, 5, 5, 5, 5, 6,
    6, 6, 6, 6, 6, 6, 7, 7, 7, 7, 7, 7, 8, 8, 8, 8, 8, 9, 9, 9, 9);
const uint kGramJ[kGram] = uint[kGram](
    0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 2, 3, 4, 5, 6,
    7, 8, 9, 10, 11, 12, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 4, 5, 6, 7, 8, 9, 10, 11, 12, 5, 6, 7, 8,
    9, 10, 11, 12, 6, 7, 8, 9, 10, 11, 12, 7, 8, 9, 10, 11, 12, 8, 9, 10, 11, 12, 9, 10, 11, 12);

shared float s_partial[kChunk][kGroup];
shared float s_result[kGram];
shared float s_r[kM][kCols];
shared float s_coef[3][kM];
shared uint s_cell[1024];

// Index of Gram entry (k, j), j >= k, in row-major order of the upper rows.
uint gram_index(uint k, uint j) { return k * kCols - (k * (k - 1u)) / 2u + (j - k); }

// Max (bit j of max_mask set) or sum (clear) of each of vals[0..n) over the workgroup, in
// rounds of kChunk values: each invocation stores its values, then invocation v folds value
// v over the group serially (on lavapipe several times faster than subgroup reductions,
// which loop over the lanes of every subgroup for every value). With FOVEA_SUBGROUP_REDUCE
// each subgroup reduces its values first and one of its invocations stores them: the fold
// then runs over the subgroups (8 of 32 lanes on a 256-wide group), not the invocations.
// Results in s_result.
void reduce(inout float vals[kGram], const uint n, const uint max_mask) {
#ifdef FOVEA_SUBGROUP_REDUCE
  const uint slot = gl_SubgroupID, slots = gl_NumSubgroups;
#else
  const uint slot = gl_LocalInvocationIndex, slots = kGroup;
#endif
  for (uint base = 0u; base < n; base += kChunk) {
    [[unroll]] for (uint j = 0u; j < n; ++j)
      if (j >= base && j < base + kChunk) {
        bool is_max = j < 32u && ((max_mask >> j) & 1u) != 0u;
#ifdef FOVEA_SUBGROUP_REDUCE
        float v = is_max ? subgroupMax(vals[j]) : subgroupAdd(vals[j]);
        if (subgroupElect()) s_partial[j - base][slot] = v;
#else
        s_partial[j - base][slot] = vals[j];
#endif
      }
    barrier();
    for (uint v = gl_LocalInvocationIndex; v < kChunk && base + v < n; v += kGroup) {
      bool is_max = base + v < 32u && ((max_mask >> (base + v)) & 1u) != 0u;
      float acc = s_partial[v][0];
      for (uint g = 1u; g < slots; ++g) acc = is_max ? max(acc, s_partial[v][g]) : acc + s_partial[v][g];
      s_result[base + v] = acc;
    }
    barrier();
  }
}

float to_storage(float v) { return kFp16 ? unpackHalf2x16(packHalf2x16(vec2(v, 0.0))).x : v; }

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

bool inside(ivec2 c) { return c.x >= 0 && c.y >= 0 && c.x < int(pc.padded_columns) && c.y < int(pc.padded_rows); }

// Cholesky factor R of the block's Gram matrix (in s_result) into s_r, then back substitution
// R α = r per channel (Eq. 5) into s_coef; one invocation. Dropped pivots (dependent
// features the noise did not lift) leave a zero row and a zero coefficient.
void solve() {
  for (uint k = 0u; k < kM; ++k) {
    float gkk = s_result[gram_index(k, k)];
    float d = gkk;
    for (uint i = 0u; i < k; ++i) d -= s_r[i][k] * s_r[i][k];
    bool keep = gkk > 1e-30 && d > kPivot * gkk;
    float rkk = keep ? sqrt(d) : 0.0;
    s_r[k][k] = rkk;
    for (uint j = k + 1u; j < kCols; ++j) {
      float a = s_result[gram_index(k, j)];
      for (uint i = 0u; i < k; ++i) a -= s_r[i][k] * s_r[i][j];
      s_r[k][j] = keep ? a / rkk : 0.0;
    }
  }
  for (uint c = 0u; c < 3u; ++c)
    for (int k = int(kM) - 1; k >= 0; --k) {
      float acc = s_r[k][kM + c];
      for (uint j = uint(k) + 1u; j < kM; ++j) acc -= s_r[k][j] * s_coef[c][j];
      float a = s_r[k][k] > 0.0 ? acc / s_r[k][k] : 0.0;
      s_coef[c][k] = (isnan(a) || isinf(a)) ? 0.0 : a;
    }
}

void main() {
  uint tid = gl_LocalInvocationIndex;
  float vals[kGram];

  // Pass 1, one reduction over the valid rows: maxima of the position range (max of w and
  // −w), of whether any row is valid and of the input; sums of the input (rgb) and of the rows.
  [[unroll]] for (uint j = 0u; j < kGram; ++j) vals[j] = j < 8u ? -3.0e38 : 0.0;
  [[dont_unroll]] for (uint q = 0u; q < kRows; ++q) {
    uint row = tid + q * kGroup;
    ivec2 c = cell_of(row);
    s_cell[row] = kOutside;
    if (!inside(c)) continue;
    uint i = uint(c.y) * pc.padded_columns + uint(c.x);
    s_cell[row] = i | kMasked;
    vec4 p = texelFetch(vpos, int(i));
    // Sky, emitter, no sample, metal, edge.
    if (p.w < 0.0 || !has_diffuse(p.w) || texelFetch(edge, int(i)).x != 0u) continue;
    s_cell[row] = i;
    vec3 zin = texelFetch(z, int(i)).rgb;
    [[unroll]] for (uint a = 0u; a < 3u; ++a) {
      vals[a] = max(vals[a], p[a]);
      vals[3u + a] = max(vals[3u + a], -p[a]);
    }
    vals[6] = 1.0;
    vals[7] = max(vals[7], max(max(zin.r, zin.g), zin.b));
    [[unroll]] for (uint a = 0u; a < 3u; ++a) vals[8u + a] += zin[a];
    vals[11] += 1.0;
  }
  reduce(vals, 12u, 0xFFu);
  vec3 wmax = vec3(s_result[0], s_result[1], s_result[2]), wmin = -vec3(s_result[3], s_result[4], s_result[5]);
  float any_valid = s_result[6], count = max(s_result[11], 1.0);
  // Outliers stay out of the fit (deviation from Koskela): the regression sees the input
  // clamped to kOutlier × its block mean per channel, and each cell's excess goes to the
  // excess buffer, added back after Phase III (recon_post.comp): no energy is lost and none
  // is spread. A firefly (e.g. a caustic: floor → glossy sphere → light, 300× the mean at
  // 1 spp) otherwise lifts its whole block (docs/reconstruction.md, glossy-spheres).
  vec3 bound = kOutlier * vec3(s_result[8], s_result[9], s_result[10]) / count;
  // z enters the regression divided by its (clamped) block maximum (the fit is linear in z,
  // so the fitted values scale back): every column then stays within fp16 range.
  float zmax = min(s_result[7], max(max(bound.r, bound.g), bound.b));
  zmax = zmax > 0.0 ? zmax : 1.0;

  // Blocks without a surface sample only pass sky through (uniform branch: no barrier inside).
  if (any_valid < 0.5) {
    [[dont_unroll]] for (uint q = 0u; q < kRows; ++q) {
      uint cell = s_cell[tid + q * kGroup];
      if (cell == kOutside) continue;
      uint i = cell & ~kMasked;
      fitted[i] = rg_no_sample(texelFetch(vpos, int(i)).w) ? vec4(0.0) : texelFetch(z, int(i));
      excess[i] = vec4(0.0);
    }
    return;
  }

  vec3 mid = 0.5 * (wmax + wmin);
  vec3 half_range = 0.5 * (wmax - wmin);
  vec3 inv_half = vec3(half_range.x > 1e-6 ? 1.0 / half_range.x : 0.0, half_range.y > 1e-6 ? 1.0 / half_range.y : 0.0,
                       half_range.z > 1e-6 ? 1.0 / half_range.z : 0.0);

  // Pass 2: block means of the features n, w, w² (the shifts).
  [[unroll]] for (uint j = 0u; j < kGram; ++j) vals[j] = 0.0;
  [[dont_unroll]] for (uint q = 0u; q < kRows; ++q) {
    uint cell = s_cell[tid + q * kGroup];
    if (cell >= kMasked) continue;
    vec3 n = texelFetch(vnrm, int(cell)).xyz;
    vec3 w = clamp((texelFetch(vpos, int(cell)).xyz - mid) * inv_half, -1.0, 1.0);
    [[unroll]] for (uint a = 0u; a < 3u; ++a) {
      vals[a] += n[a];
      vals[3u + a] += w[a];
      vals[6u + a] += w[a] * w[a];
    }
  }
  reduce(vals, 9u, 0u);
  vec3 mean_n = vec3(s_result[0], s_result[1], s_result[2]) / count;
  vec3 mean_w = vec3(s_result[3], s_result[4], s_result[5]) / count;
  vec3 mean_w2 = vec3(s_result[6], s_result[7], s_result[8]) / count;

  // Pass 3: the Gram matrix of [T + N | z], streamed row by row.
  [[unroll]] for (uint j = 0u; j < kGram; ++j) vals[j] = 0.0;
  [[dont_unroll]] for (uint q = 0u; q < kRows; ++q) {
    uint row = tid + q * kGroup;
    uint cell = s_cell[row];
    if (cell >= kMasked) continue;
    vec3 n = texelFetch(vnrm, int(cell)).xyz - mean_n;
    vec3 w = clamp((texelFetch(vpos, int(cell)).xyz - mid) * inv_half, -1.0, 1.0);
    vec3 w2 = w * w - mean_w2;
    w -= mean_w;
    vec3 zz = min(texelFetch(z, int(cell)).rgb, bound) / zmax;
    float t[kCols] = float[kCols](1.0, n.x, n.y, n.z, w.x, w.y, w.z, w2.x, w2.y, w2.z, zz.r, zz.g, zz.b);
    // Eq. 7: zero-mean uniform noise on the non-constant features, keyed by block, row, feature, frame.
    [[unroll]] for (uint j = 1u; j < kCols; ++j) {
      float noise = 0.0;
      if (j < kM) noise = pc.noise * (2.0 * hash_to_unit(hash3(gl_WorkGroupID.x * 1024u + row, j, pc.frame)) - 1.0);
      t[j] = to_storage(t[j] + noise);
    }
    [[unroll]] for (uint e = 0u; e < kGram; ++e) vals[e] += t[kGramK[e]] * t[kGramJ[e]];
  }
  reduce(vals, kGram, 0u);
  if (tid == 0u) solve();
  barrier();

  // Pass 4: weighted sum with the noise-free (shifted) features (Eq. 6); negative fits clamp to 0.
  [[dont_unroll]] for (uint q = 0u; q < kRows; ++q) {
    uint cell = s_cell[tid + q * kGroup];
    if (cell == kOutside) continue;
    uint i = cell & ~kMasked;
    vec4 zi = texelFetch(z, int(i));
    if (cell >= kMasked) {
      fitted[i] = rg_no_sample(texelFetch(vpos, int(i)).w) ? vec4(0.0) : zi;
      excess[i] = vec4(0.0);
      continue;
    }
    excess[i] = vec4(max(zi.rgb - bound, vec3(0.0)), 0.0);
    vec3 n = texelFetch(vnrm, int(i)).xyz - mean_n;
    vec3 w = clamp((texelFetch(vpos, int(i)).xyz - mid) * inv_half, -1.0, 1.0);
    vec3 w2 = w * w - mean_w2;
    w -= mean_w;
    float t[kM] = float[kM](1.0, n.x, n.y, n.z, w.x, w.y, w.z, w2.x, w2.y, w2.z);
    vec3 y = vec3(0.0);
    [[unroll]] for (uint m = 0u; m < kM; ++m) y += vec3(s_coef[0][m], s_coef[1][m], s_coef[2][m]) * t[m];
    y = clamp(y * zmax, vec3(0.0), vec3(1e9));
    // .w: the samples behind the input (its count), Phase III's weight for this fit.
    fitted[i] = vec4(isnan(y.r) || isnan(y.g) || isnan(y.b) ? vec3(0.0) : y, zi.w);
  }
}
