#version 460
// Albedo re-modulation and TAA in grid space (Koskela et al. 2019 §3.5, Karis 2014; P5 §3.3:
// in Visual-Polar space, since screen-space TAA would jitter too much in the fovea): the
// reprojected history (same taps as Phase I) is clamped to the YCoCg min/max of the cell's
// 3×3 grid neighbourhood (neighbouring columns at the same φ) and blended with α_taa.
// Deviations from the BMFR reference code, measured in docs/reconstruction.md:
// - Clamp and blend act on c / (1 + luma(c)) (Karis 2014's perceptual weighting; the
//   reference code runs its TAA on clipped, tone-mapped colour): with sub-cell jitter a cell
//   straddling an emitter and a dark surface in front of it averages their linear radiance,
//   which the emitter dominates (thin occluders vanished; stereo-occluders 36–54°).
// - α = max(1/n, α_taa), n the cell's Phase I sample count: a history that just started over
//   (disocclusion, a saccade's new fovea) is averaged evenly like Phase I's, instead of its
//   first noisy frame keeping weight 0.8.
// - The current sample's weight falls with its jitter offset from the cell centre (Gaussian,
//   σ = kCentreSigma cells; Karis 2014 weights current samples by a reconstruction filter of
//   their distance to the pixel centre): the history converges to a centre-weighted mean of
//   the cell instead of its box mean, which the resolve's tent between cells blurs further
//   (docs/reconstruction.md, "Jitter and reprojection"; stereo-occluders 40–42°). Not on a
//   grid that is the display's own raster (full Cartesian, linear fall-off): the resolve
//   reads its cells at the pixels' centres without a tent, so the box mean is what a pixel
//   of the reference holds; there the weight only lengthened TAA's memory (its mean is
//   ~0.36) and cost 0.2–4 dB along a moving gaze (docs/sweep.md).
// - In the frames after Phase I rejected a cell's history as too coarse (a saccade's new
//   fovea; kReconRestartFrames, never at a still gaze) the current input is first averaged
//   with the grid neighbours that pass the history's validity test (same surface): 5×5 in
//   the first kRestartFollow frames, 3×3 after. The first frame is shown without TAA's
//   history (it holds the coarse periphery); in the rest of the window TAA is a running
//   mean weighted by the jitter's centre weight g, α = g / (ḡ·(k − 1) + g) at the
//   window's frame k (ḡ: g's mean over the cell), so the window's frames count about evenly
//   and the albedo, re-modulated from each frame's jittered sample, converges to the cell
//   centre's as with a fixed gaze. (With jitter off, g = 1, the newest frame weighs more;
//   an even mean measured worse, the input already being Phase I's mean of the window.)
//   The new fovea starts over with a few samples per cell against a fixed gaze's long
//   history (docs/reconstruction.md, "Saccade recovery curve").
// - The history is read with Catmull–Rom over 4 columns × 4 rows (each column at its own row
//   coordinate; Karis 2014 reads it bicubic too) where Phase I kept all four bilinear taps
//   (one surface, no coarser cells) and every tap holds a sample; else with Phase I's taps.
//   The bilinear taps blur the history once more on every frame the grid moves; Catmull–Rom
//   keeps more of it (fove0, gaze recording: fovea PSNR +0.16 dB), and the neighbourhood
//   clamp takes its overshoot (docs/reconstruction.md,
//   "Textures under sparse cells, fireflies, history resampling").
// - Fireflies are capped before the resolve spreads a cell over its pixels (a peripheral cell
//   at a low budget covers tens of them): a surface cell's output luminance is at most
//   kFireflyRatio times the brightest of its 3×3 grid neighbours' inputs. Only an isolated
//   maximum is touched (a highlight or an edge has a bright neighbour), emitters and the sky
//   never; the cap acts on the output only, so Phase I's history keeps the sample and the
//   still image still converges (same section).
// .w = 1 marks cells holding a sample (the resolve renormalises over them).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers

layout(local_size_x = 64) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/pt_trace.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(binding = RECON_TABLES) uniform textureBuffer tables;  // GridColumn: rg_table()
layout(binding = RECON_TAA_POS) uniform textureBuffer vpos;
layout(binding = RECON_TAA_TAP_IDX) uniform utextureBuffer tap_idx;
layout(binding = RECON_TAA_TAP_W) uniform textureBuffer tap_w;
layout(binding = RECON_TAA_POST) uniform textureBuffer post;
layout(binding = RECON_TAA_ALBEDO) uniform textureBuffer albedo;
layout(binding = RECON_TAA_PREV_FINAL) uniform textureBuffer prev_final;
layout(std430, binding = RECON_TAA_FINAL) writeonly buffer Final { vec4 final_color[]; };
layout(binding = RECON_TAA_NRM) uniform textureBuffer vnrm;
layout(binding = RECON_TAA_RESTART) uniform textureBuffer restart;  // Phase I's window
// The albedo the output holds: the re-modulation's, blended with the history's as the colour
// is (linearly, with the same weights), so that the resolve can take it out again where the
// display pixels' own albedo re-modulates the fovea (recon_resolve.comp, detail_gain).
// Only where the resolve asks for it (kFinalAlbedo; otherwise its buffers are not the grid's size).
layout(binding = RECON_TAA_PREV_FINAL_ALBEDO) uniform textureBuffer prev_final_albedo;
layout(std430, binding = RECON_TAA_FINAL_ALBEDO) writeonly buffer FinalAlbedo { vec4 final_albedo[]; };
layout(constant_id = 0) const bool kFinalAlbedo = false;

#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconPostPush pc; };
#define LIVE_CELLS_LAYOUT layout(std430, binding = RECON_TAA_LIVE)
#include "fovea/shaders/live_cells.h"

const float kCentreSigma = 0.25;
// ḡ: the mean of exp(−|j|²/(2σ²)) over a uniform jitter j in the cell, (σ√(2π) erf(1/(2√2 σ)))².
const float kMeanCentre = 0.358;
const float kFireflyRatio = 4.0;   // a surface cell's luminance over its brightest neighbour's, at most
const float kRestartFollow = 4.0;  // restart frames with the 5×5 average
const int kRestartReach = 2;       // the 5×5 average's reach (cells)

vec3 to_ycocg(vec3 c) {
  return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}
vec3 from_ycocg(vec3 y) { return vec3(y.x + y.y - y.z, y.x + y.z, y.x - y.y - y.z); }

// The perceptual weighting and its inverse (luma(c / (1 + luma c)) < 1).
float luma(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }
vec3 compress(vec3 c) { return c / (1.0 + luma(c)); }
vec3 expand(vec3 c) { return c / max(1.0 - luma(c), 1e-6); }

vec3 remodulated(uint i) {
  return texelFetch(post, int(i)).rgb * max(texelFetch(albedo, int(i)).rgb, vec3(kPtMinDemodAlbedo));
}

// The history at grid coordinate uv of the previous mapping by Catmull–Rom, in the compressed
// space, where Phase I kept all four bilinear taps of uv at their bilinear weights `kept` (no
// tap rejected as another surface or reweighted as coarser; the bilinear weights come from
// the middle two of the four columns, each column's entry read once); false otherwise, or
// when a tap holds no sample (the caller then keeps Phase I's taps).
bool history_catmull_rom(ReconGrid prev, vec2 uv, vec4 kept, out vec3 h, out vec3 ha) {
  h = vec3(0.0);
  ha = vec3(0.0);
  float uc = uv.x - 0.5, c0f = floor(uc), fx = uc - c0f;
  vec4 wx = rg_catmull_rom(fx);
  bool ok = true;
  for (int a = 0; a < 4; ++a) {
    uint c = uint(clamp(int(c0f) - 1 + a, 0, int(prev.g.columns) - 1));
    GridColumn col = rg_column(prev, c);
    int rows = int(max(col.rows, 1u));
    bool wraps = rg_column_wraps(prev, col);
    float vr = rg_row_coord_of(col, uv.y) - 0.5, r0f = floor(vr), fy = vr - r0f;
    if (a == 1 || a == 2) {  // rg_taps' columns and weights
      float wc = a == 1 ? 1.0 - fx : fx;
      vec2 d = abs(vec2(wc * (1.0 - fy), wc * fy) - (a == 1 ? kept.xy : kept.zw));
      ok = ok && max(d.x, d.y) < 1e-4;
    }
    vec4 wy = rg_catmull_rom(fy);
    for (int b = 0; b < 4; ++b) {
      int r = int(r0f) - 1 + b;
      r = wraps ? rg_wrap(r, rows) : clamp(r, 0, rows - 1);
      int j = int(uint(r) * prev.g.padded_columns + c);
      vec4 v = texelFetch(prev_final, j);
      if (v.w <= 0.0) return false;
      h += wx[a] * wy[b] * compress(v.rgb);
      if (kFinalAlbedo) ha += wx[a] * wy[b] * texelFetch(prev_final_albedo, j).rgb;
    }
  }
  return ok;
}

// The history of a cell of column `col` whose sample is `here` (position, code) by
// Catmull–Rom, where Phase I kept all its bilinear taps `kept` and every tap holds a sample.
bool sharp_history(ReconGrid cur, uint col, vec4 here, vec4 kept, out vec3 h, out vec3 ha) {
  h = vec3(0.0);
  ha = vec3(0.0);
  ReconGrid prev = maps[kReconPrevious];
  vec2 uv;
  if (!rg_world_to_grid(prev, here.xyz, abs(here.w - kReconSky) < 0.5, false, uv)) return false;
  return history_catmull_rom(prev, rg_unjitter(cur, rg_column(cur, col), prev, uv), kept, h, ha);
}

vec3 capped(vec3 c, float cap) {
  float l = luma(c);
  return l > cap ? c * (cap / l) : c;
}

void main() {
  const uint i = cell_of_invocation(pc.cells, pc.listed != 0u);
  if (i == kNoLiveCell) return;
  if (rg_no_sample(texelFetch(vpos, int(i)).w)) {
    final_color[i] = vec4(0.0);
    if (kFinalAlbedo) final_albedo[i] = vec4(0.0);
    return;
  }
  ReconGrid m = maps[kReconCurrent];
  bool denoise = pc.denoise != 0u;
  vec4 w = texelFetch(tap_w, int(i));
  bool history = pc.has_history != 0u && w.x + w.y + w.z + w.w > 0.0;
  // Frames since Phase I restarted the cell's history (0: none recent); its window's
  // neighbour average and running mean belong to the denoised path.
  float since = denoise ? texelFetch(restart, int(i)).x : 0.0;
  vec3 lo = vec3(3.0e38), hi = vec3(-3.0e38);
  float brightest = -1.0;  // the largest luminance of the 3×3 neighbours' inputs (the firefly cap)
  vec4 here = texelFetch(vpos, int(i)), nd = texelFetch(vnrm, int(i));
  vec3 avg = texelFetch(post, int(i)).rgb;
  float avg_w = 1.0;
  RgCell cell = rg_cell(m, i);
  bool follow = since > 0.0;  // the window: TAA's running mean
  int reach = follow && since <= kRestartFollow ? kRestartReach : 1;
  for (int dc = -reach; dc <= reach; ++dc) {
    RgColumnNear near;
    if (!rg_column_next_to(m, cell, dc, near)) continue;
    for (int dr = -reach; dr <= reach; ++dr) {
      uint j;
      if (!rg_row_next_to(m, near, dr, j) || rg_no_sample(texelFetch(vpos, int(j)).w)) continue;
      if (abs(dc) <= 1 && abs(dr) <= 1) {  // the clamp's and the cap's 3×3 neighbourhood
        vec3 r = remodulated(j);
        vec3 y = to_ycocg(compress(r));
        lo = min(lo, y);
        hi = max(hi, y);
        if ((dc != 0 || dr != 0) && j != i) brightest = max(brightest, luma(r));
      }
      if (since > 0.0 && (dc != 0 || dr != 0) &&
          rg_tap_valid(here, nd.xyz, nd.w, texelFetch(vpos, int(j)), texelFetch(vnrm, int(j)).xyz)) {
        avg += texelFetch(post, int(j)).rgb;  // the same surface's demodulated input
        avg_w += 1.0;
      }
    }
  }
  // No cap for emitters, the sky and a cell without neighbours.
  float cap = here.w < 0.0 || brightest < 0.0 ? 3.0e38 : kFireflyRatio * brightest;
  vec3 alb = max(texelFetch(albedo, int(i)).rgb, vec3(kPtMinDemodAlbedo));
  vec3 c = avg / avg_w * alb;
  // The frame a gaze jump lands (ReconSettings::landing_deg): the new fovea's history is the
  // previous frame's periphery resampled, too coarse to blend in, yet mostly within the
  // coarse-cell test's limits; blended, it made BMFR's landed fovea worse than no denoiser's.
  if (pc.landing_deg > 0.0) {
    vec3 d = normalize(rg_world_to_view(m, here.xyz, abs(here.w - kReconSky) < 0.5));
    if (dot(d, vec3(m.g.gaze_x, m.g.gaze_y, m.g.gaze_z)) >= cos(radians(pc.landing_deg))) history = false;
  }
  // Accumulation only, nothing to blend, a history that is the coarse periphery's, or a still
  // view outside a restart window, whose blend below would take the current value alone
  // (a = 1): its history is neither read nor clamped.
  if (!denoise || !history || since == 1.0 || (pc.still >= 1.0 && !follow)) {
    final_color[i] = vec4(capped(c, cap), 1.0);
    if (kFinalAlbedo) final_albedo[i] = vec4(alb, 1.0);
    return;
  }
  vec3 h, ha;
  if (!sharp_history(m, cell.col, here, w, h, ha)) {
    uvec4 idx = texelFetch(tap_idx, int(i));
    h = vec3(0.0);
    ha = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
      h += w[k] * compress(texelFetch(prev_final, int(idx[k])).rgb);
      if (kFinalAlbedo) ha += w[k] * texelFetch(prev_final_albedo, int(idx[k])).rgb;
    }
  }
  h = from_ycocg(clamp(to_ycocg(h), lo, hi));
  vec2 jitter = vec2(m.g.jitter_u, m.g.jitter_v);  // the sample's offset from the cell centre (cells)
  bool weighted = !(m.g.family == kFamilyCartesian && float(m.g.columns) == m.g.width && float(m.g.rows) == m.g.height);
  float g = weighted ? exp(-dot(jitter, jitter) / (2.0 * kCentreSigma * kCentreSigma)) : 1.0;
  float a = follow ? g / ((weighted ? kMeanCentre : 1.0) * (since - 1.0) + g)
                   : max(1.0 / max(texelFetch(post, int(i)).w, 1.0), pc.taa_alpha) * g;
  // A still view (pc.still 1, returned above) needs no TAA outside a restart window, and a
  // slow one leans toward it (pc.still between 0 and 1): Phase I's cumulative
  // mean of the jittered samples is each cell's box-filtered mean already, and TAA's blend
  // kept a bias that never averages out (measured, docs/reconstruction-history.md "TAA on a
  // still view and the fit's hand-over: tried and not taken": with the clamp; without it in
  // the compressed space; in linear space as a weighted cumulative mean). A restart window
  // keeps its running mean: its history is young.
  if (!follow) a = mix(a, 1.0, pc.still);
  final_color[i] = vec4(capped(max(expand(mix(h, compress(c), a)), vec3(0.0)), cap), 1.0);
  if (kFinalAlbedo) final_albedo[i] = vec4(max(mix(ha, alb, a), vec3(kPtMinDemodAlbedo)), 1.0);
}
