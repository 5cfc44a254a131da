#version 460
// BMFR Phase I in grid space (Koskela et al. 2019 §3.2; Koskela et al. 2019 P5 §3.3): each
// sample's world position is reprojected into the previous frame's view and grid mapping
// (the gaze moved), the history is fetched bilinearly with a validity test per tap,
// renormalised over the accepted taps, and blended with α = max(1/n, α_min) (CMA, then EMA).
// Taps are read at the cell centre (the frame's sub-cell jitter taken off) and count as valid
// when the sample's surface was seen in the tap's cell or next to it (seen_near); taps from
// cells coarser than the sample's own are down-weighted or rejected (rg_coarse_weight).
// Direct+specular and indirect diffuse are accumulated separately (the indirect one is
// shared between the eyes later); each carries its own 8-bit sample count in .w. The first
// hit's albedo is accumulated with the direct light's weights, so textures are re-modulated
// from the mean of the cell's jittered samples, not from one sample per frame (which aliased
// fine textures into moiré, docs/reconstruction.md "Textures under sparse cells").
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers

layout(local_size_x = 64) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/pt_scene.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(binding = RECON_TABLES) uniform textureBuffer tables;  // GridColumn: rg_table()
layout(std430, binding = RECON_ACC_SAMPLES) readonly buffer Samples { GridSample samples[]; };
layout(binding = RECON_ACC_DIRECT) uniform textureBuffer direct;
layout(binding = RECON_ACC_INDIRECT) uniform textureBuffer indirect;
layout(binding = RECON_ACC_NORMAL_DEPTH) uniform textureBuffer normal_depth;
layout(binding = RECON_ACC_POSITION_MATERIAL) uniform textureBuffer position_material;
layout(binding = RECON_ACC_PREV_DIRECT) uniform textureBuffer prev_direct;
layout(binding = RECON_ACC_PREV_INDIRECT) uniform textureBuffer prev_indirect;
layout(binding = RECON_ACC_PREV_POS) uniform textureBuffer prev_pos;
layout(binding = RECON_ACC_PREV_NRM) uniform textureBuffer prev_nrm;
layout(std430, binding = RECON_ACC_OUT_DIRECT) writeonly buffer AccDirect { vec4 acc_direct[]; };
layout(std430, binding = RECON_ACC_OUT_INDIRECT) writeonly buffer AccIndirect { vec4 acc_indirect[]; };
layout(std430, binding = RECON_ACC_OUT_POS) writeonly buffer Pos { vec4 vpos[]; };
layout(std430, binding = RECON_ACC_OUT_NRM) writeonly buffer Nrm { vec4 vnrm[]; };
layout(std430, binding = RECON_ACC_TAP_IDX) writeonly buffer TapIdx { uvec4 tap_idx[]; };
layout(std430, binding = RECON_ACC_TAP_W) writeonly buffer TapW { vec4 tap_w[]; };
layout(std430, binding = RECON_ACC_MATERIALS) readonly buffer Materials { PtMaterial materials[]; };
layout(binding = RECON_ACC_PREV_RESTART) uniform textureBuffer prev_restart;
layout(std430, binding = RECON_ACC_OUT_RESTART) writeonly buffer Restart { float restart[]; };
layout(binding = RECON_ACC_LUTS) uniform utextureBuffer radius_luts;
layout(binding = RECON_ACC_ALBEDO) uniform textureBuffer albedo;  // the tracer's, this frame
layout(binding = RECON_ACC_PREV_ALBEDO) uniform textureBuffer prev_albedo;
layout(std430, binding = RECON_ACC_OUT_ALBEDO) writeonly buffer AccAlbedo { vec4 acc_albedo[]; };

#define RG_RADIUS_LUT
#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconAccumulatePush pc; };
#define LIVE_CELLS_LAYOUT layout(std430, binding = RECON_ACC_LIVE)
#include "fovea/shaders/live_cells.h"

// Whether the previous frame saw the sample's surface (rg_tap_valid) in cell j of mapping m
// or next to it. With sub-cell jitter a cell on an edge sees one side or the other from
// frame to frame; its history stands for the cell's whole area, so it stays valid as long
// as the surface now hit was seen within a cell of it. A disocclusion has no such neighbour.
bool seen_near(ReconGrid m, uint j, vec4 here, vec3 n, float depth) {
  if (rg_no_sample(texelFetch(prev_pos, int(j)).w)) return false;
  // The cell itself: the usual case.
  if (rg_tap_valid(here, n, depth, texelFetch(prev_pos, int(j)), texelFetch(prev_nrm, int(j)).xyz)) return true;
  RgCell cell = rg_cell(m, j);
  for (int dc = -1; dc <= 1; ++dc) {
    RgColumnNear near;
    if (!rg_column_next_to(m, cell, dc, near)) continue;
    for (int dr = -1; dr <= 1; ++dr) {
      uint k;
      if ((dc != 0 || dr != 0) && rg_row_next_to(m, near, dr, k) &&
          rg_tap_valid(here, n, depth, texelFetch(prev_pos, int(k)), texelFetch(prev_nrm, int(k)).xyz))
        return true;
    }
  }
  return false;
}

// The cell's angular size (degrees): its sample spacing in display pixels times a pixel's
// smaller angle at its direction.
float cell_deg(ReconGrid m, GridSample s) {
  vec2 t = vec2(s.dir_x, s.dir_y) / max(-s.dir_z, 1e-6);
  return degrees(s.footprint * min(rg_pixel_angle(m, t, false), rg_pixel_angle(m, t, true)));
}

void main() {
  const uint i = cell_of_invocation(pc.cells, pc.listed != 0u);
  if (i == kNoLiveCell) return;
  GridSample s = samples[i];
  if (s.flags != 0u) {
    acc_direct[i] = vec4(0.0);
    acc_indirect[i] = vec4(0.0);
    acc_albedo[i] = vec4(0.0);
    vpos[i] = vec4(0.0, 0.0, 0.0, kReconNoSample);
    vnrm[i] = vec4(0.0);
    tap_idx[i] = uvec4(0u);
    tap_w[i] = vec4(0.0);
    restart[i] = 0.0;
    return;
  }
  ReconGrid cur = maps[kReconCurrent];
  vec4 pm = texelFetch(position_material, int(i));
  bool sky = pm.w < 0.0;
  vec3 eye = vec3(cur.eye_x, cur.eye_y, cur.eye_z);
  vec3 p = sky ? normalize(rg_view_to_world_dir(cur, vec3(s.dir_x, s.dir_y, s.dir_z))) : pm.xyz;
  vec3 n = texelFetch(normal_depth, int(i)).xyz;
  float depth = sky ? 0.0 : length(pm.xyz - eye);
  float code = kReconSky;
  if (!sky) {
    PtMaterial mat = materials[uint(pm.w)];
    code = max(max(mat.emit_r, mat.emit_g), mat.emit_b) > 0.0 ? kReconEmitterBase - pm.w : pm.w;
  }
  vec4 here = vec4(p, code);
  vpos[i] = here;
  vnrm[i] = vec4(n, depth);

  vec4 hd = vec4(0.0), hi = vec4(0.0), ha = vec4(0.0);
  uvec4 idx = uvec4(0u);
  vec4 w = vec4(0.0);
  float confidence = 0.0;  // the history's share: valid taps, less for coarser cells
  float since = 0.0;       // frames since a restart for coarse cells (kReconRestartFrames)
  if (pc.has_history != 0u && maps[kReconPrevious].valid != 0u) {
    ReconGrid prev = maps[kReconPrevious];
    vec2 uv;
    // An unmoved grid (the previous frame's but for the jitter: a still view whose layout
    // held) holds each cell's history in the cell itself, which reprojecting the jittered
    // sample finds only up to rounding (the rest of the bilinear weight on its neighbours).
    bool unmoved = pc.unmoved != 0u;
    if (unmoved || rg_world_to_grid(prev, p, sky, true, uv)) {
      GridColumn col = rg_column(cur, i % cur.g.padded_columns);
      float own = rg_column_cell_size(cur, col), valid = 0.0, kept = 0.0;
      uvec2 cols;
      vec2 sizes = vec2(own);
      if (unmoved) {
        idx = uvec4(i);
        w = vec4(1.0, 0.0, 0.0, 0.0);
      } else {
        rg_taps(prev, rg_unjitter(cur, col, prev, uv), idx, w, cols, sizes);
      }
      // A cell the view moved by less than kHeldCellShare of its size holds the same part of
      // the static scene as the frame before, and its history is the box mean of that area
      // whichever surfaces the jittered samples hit (a tap without a sample still counts for
      // nothing): tested by surface, a large cell on an edge or against the sky restarted
      // whenever its sample changed sides, never converged and showed single samples as blobs.
      bool held = pc.held_deg <= cell_deg(cur, s);
      vec2 coarse = vec2(rg_coarse_weight(sizes.x, own, pc.coarse_keep, pc.coarse_reject),
                         rg_coarse_weight(sizes.y, own, pc.coarse_keep, pc.coarse_reject));
      for (int k = 0; k < 4; ++k) {
        bool usable = w[k] > 0.0 && (held ? !rg_no_sample(texelFetch(prev_pos, int(idx[k])).w)  // any surface, not none
                                          : seen_near(prev, idx[k], here, n, depth));
        if (!usable) w[k] = 0.0;
        valid += w[k];
        w[k] *= coarse[k >> 1];
        kept += w[k];
      }
      if (kept > 1e-4) {
        confidence = kept / valid;
        w /= kept;
        for (int k = 0; k < 4; ++k) {
          hd += w[k] * texelFetch(prev_direct, int(idx[k]));
          hi += w[k] * texelFetch(prev_indirect, int(idx[k]));
          ha += w[k] * texelFetch(prev_albedo, int(idx[k]));
          if (w[k] > 0.0) since = max(since, texelFetch(prev_restart, int(idx[k])).x);
        }
      } else {
        w = vec4(0.0);
      }
      // A history mostly rejected as too coarse starts a restart window; a kept one carries
      // its window on. Never at a still gaze (same cell sizes).
      if (valid > 0.0 && kept < 0.5 * valid) since = 1.0;
      else since = since > 0.0 && since < kReconRestartFrames ? since + 1.0 : 0.0;
    }
  }
  tap_idx[i] = idx;
  tap_w[i] = w;
  restart[i] = since;
  // Counts are fetched with the same weights and rounded (BMFR §3.2); a partly coarse
  // history counts for its share only, which raises α.
  hd.w *= confidence;
  hi.w *= confidence;
  // On the frame a gaze jump lands, the new fovea's history is the periphery's, resampled
  // from another layout: it counts for pc.landing_history samples at most, so that the
  // landing's own samples outweigh its blur within a few frames instead of the tens of
  // frames its full count would take (docs/reconstruction.md, "A 32° gaze step").
  if (pc.landing_deg > 0.0 && s.ecc_deg <= pc.landing_deg) {
    hd.w = min(hd.w, pc.landing_history);
    hi.w = min(hi.w, pc.landing_history);
  }
  // This frame's mean holds `held` samples (the tracer's .a: more in a new fovea's first
  // frames), so it counts for that many.
  vec4 now_d = texelFetch(direct, int(i));
  float held = max(now_d.w, 1.0);
  float nd = min(round(hd.w) + held, 255.0);
  float ad = max(held / nd, pc.alpha_min);
  acc_direct[i] = vec4(mix(hd.rgb, now_d.rgb, ad), nd);
  // The albedo with the direct light's weights where the history sits on the cell (a still
  // grid): the jittered first hits average to the texture's box filter over the cell. Where
  // the grid moved, every frame's bilinear resampling would blur it further (measured: a
  // fine texture under a drifting gaze lost most of its contrast), so the history fades out
  // as the nearest tap's weight falls from 0.99 to 0.9 (≈ 0.05 cells off) and the cell takes
  // this frame's sample, which the tracer prefilters (PathConfig::texture_cone: half the
  // cell's size on a jittered grid, the cell's without jitter).
  float aligned = clamp((max(max(w.x, w.y), max(w.z, w.w)) - 0.9) / 0.09, 0.0, 1.0);
  acc_albedo[i] = vec4(mix(ha.rgb, texelFetch(albedo, int(i)).rgb, mix(1.0, ad, aligned)), 1.0);
  if (pc.indirect_fresh != 0u) {
    vec4 now_i = texelFetch(indirect, int(i));
    float ni = min(round(hi.w) + max(now_i.w, 1.0), 255.0);
    float ai = max(max(now_i.w, 1.0) / ni, pc.alpha_min);
    acc_indirect[i] = vec4(mix(hi.rgb, now_i.rgb, ai), ni);
  } else {
    acc_indirect[i] = vec4(hi.rgb, round(hi.w));  // not traced this frame: history only
  }
}
