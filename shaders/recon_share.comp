#version 460
// Stereo sharing of indirect diffuse (Gersthofer 2020 §3.4.2): each sample gathers the other
// eye's accumulated indirect diffuse through its world position -> the other eye's view ->
// the other eye's grid, bilinear over the taps that pass the same validity test as the
// temporal reprojection (jitter taken off, coarser cells down-weighted), and combines it with
// its own, weighted by sample counts. Direct and specular light are view dependent and never
// shared. Also writes z = direct + indirect, the demodulated input of the regression, and —
// with BMFR — which cells straddle a surface edge, which the regression leaves out
// (recon_bmfr_fit.comp): this pass is the first to hold every cell's validation data of the
// frame, and the fit's workgroups would read each cell's neighbourhood in a per-block loop.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers

layout(local_size_x = 64) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(binding = RECON_TABLES) uniform textureBuffer tables;  // GridColumn: rg_table()
layout(binding = RECON_SHARE_POS) uniform textureBuffer vpos;
layout(binding = RECON_SHARE_NRM) uniform textureBuffer vnrm;
layout(binding = RECON_SHARE_ACC_DIRECT) uniform textureBuffer acc_direct;
layout(binding = RECON_SHARE_ACC_INDIRECT) uniform textureBuffer acc_indirect;
layout(binding = RECON_SHARE_OTHER_POS) uniform textureBuffer other_pos;
layout(binding = RECON_SHARE_OTHER_NRM) uniform textureBuffer other_nrm;
layout(binding = RECON_SHARE_OTHER_INDIRECT) uniform textureBuffer other_indirect;
layout(std430, binding = RECON_SHARE_SHARED) writeonly buffer Shared { vec4 shared_indirect[]; };
layout(std430, binding = RECON_SHARE_Z) writeonly buffer Z { vec4 z[]; };
layout(std430, binding = RECON_SHARE_EDGE) writeonly buffer Edge { uint edge[]; };  // 1: on a surface edge
layout(binding = RECON_SHARE_LUTS) uniform utextureBuffer radius_luts;

#define RG_RADIUS_LUT
#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconSharePush pc; };
#define LIVE_CELLS_LAYOUT layout(std430, binding = RECON_SHARE_LIVE)
#include "fovea/shaders/live_cells.h"

// Whether cell i's area straddles a surface edge: a 3×3 grid neighbour (this frame's samples)
// holds a surface the history test (rg_tap_valid) would not take for i's own. With sub-cell
// jitter Phase I keeps the history of such a cell over the samples of both sides (its area
// mean: recon_accumulate.comp, seen_near), and that mix is no function of the features of the
// side the sample hit now: fitted with its block it biased the fit at silhouettes, and the
// fit put the surface's full light where the cell's area is partly background (cornell,
// 58–60°, docs/reconstruction.md). An edge inside the cell's area always has a neighbour's
// sample on its other side, since all cells share the frame's jitter (most cells are no edge
// and test all eight neighbours).
bool straddles(ReconGrid m, uint i, vec4 here, vec4 nd) {
  RgCell cell = rg_cell(m, i);
  for (int dc = -1; dc <= 1; ++dc) {
    RgColumnNear near;
    if (!rg_column_next_to(m, cell, dc, near)) continue;
    for (int dr = -1; dr <= 1; ++dr) {
      uint k;
      if ((dc == 0 && dr == 0) || !rg_row_next_to(m, near, dr, k)) continue;
      vec4 there = texelFetch(vpos, int(k));
      if (!rg_no_sample(there.w) && !rg_tap_valid(here, nd.xyz, nd.w, there, texelFetch(vnrm, int(k)).xyz)) return true;
    }
  }
  return false;
}

void main() {
  const uint i = cell_of_invocation(pc.cells, pc.listed != 0u);
  if (i == kNoLiveCell) return;
  vec4 here = texelFetch(vpos, int(i));
  vec4 own = texelFetch(acc_indirect, int(i));
  if (rg_no_sample(here.w)) {
    shared_indirect[i] = vec4(0.0);
    z[i] = vec4(0.0);
    edge[i] = 0u;
    return;
  }
  // Only surfaces are fitted (sky and emitters, w < 0, keep their input anyway).
  edge[i] =
      pc.edges != 0u && here.w >= 0.0 && straddles(maps[kReconCurrent], i, here, texelFetch(vnrm, int(i))) ? 1u : 0u;
  vec4 result = own;
  if (pc.enabled != 0u && maps[kReconOther].valid != 0u) {
    ReconGrid other = maps[kReconOther];
    bool sky = here.w == kReconSky;
    vec2 uv;
    if (rg_world_to_grid(other, here.xyz, sky, false, uv)) {
      uvec4 idx;
      vec4 w;
      ReconGrid cur = maps[kReconCurrent];
      GridColumn col = rg_column(cur, i % cur.g.padded_columns);
      uvec2 cols;
      vec2 sizes;
      rg_taps(other, rg_unjitter(cur, col, other, uv), idx, w, cols, sizes);
      vec4 n = texelFetch(vnrm, int(i));
      float wsum = 0.0, own_size = rg_column_cell_size(cur, col);
      vec2 coarse = vec2(rg_coarse_weight(sizes.x, own_size, pc.coarse_keep, pc.coarse_reject),
                         rg_coarse_weight(sizes.y, own_size, pc.coarse_keep, pc.coarse_reject));
      vec4 acc = vec4(0.0);
      for (int k = 0; k < 4; ++k) {
        int o = int(idx[k]);
        if (w[k] <= 0.0 || !rg_tap_valid(here, n.xyz, n.w, texelFetch(other_pos, o), texelFetch(other_nrm, o).xyz)) continue;
        w[k] *= coarse[k >> 1];
        acc += w[k] * texelFetch(other_indirect, int(idx[k]));
        wsum += w[k];
      }
      if (wsum > 1e-4) {
        acc /= wsum;
        float total = own.w + acc.w;
        if (total > 0.0) result = vec4((own.w * own.rgb + acc.w * acc.rgb) / total, total);
      }
    }
  }
  shared_indirect[i] = result;
  z[i] = vec4(texelFetch(acc_direct, int(i)).rgb + result.rgb, 1.0);
}
