#version 460
// Grid generation: one GridSample (view direction, display position, flags) per cell of
// any sample distribution, from the per-frame GridParams and column table built by
// core::SampleDistribution on the CPU. Mirrors the CPU double-precision reference.
// Also counts the traced cells (flags 0) and the cells only the hidden-area mask skips, so
// nobody reads the grid back for them, and lists the live and reset cells (live_cells.h).
//
// One workgroup per tile of kPtTileColumns × kPtTileRows cells, invocation l at column
// l / kPtTileRows, row l % kPtTileRows of its tile (live_tile_cell). Each
// subgroup sets its tile's bits (a live cell, a reset cell: live_cells.h) with one atomic,
// from which grid_live_list.comp lists the tiles; no barrier: a workgroup-wide sum in shared
// memory needs barriers, which doubled this pass's time on lavapipe (fove0: 345 -> 703 ms).
// The counts take one atomic per subgroup (ballot); FOVEA_NO_BALLOT (devices without
// subgroup ballot): one per cell.
#extension GL_GOOGLE_include_directive : require
#ifndef FOVEA_NO_BALLOT
#extension GL_KHR_shader_subgroup_ballot : require
#endif

layout(local_size_x = 64) in;

#include "fovea/shaders/grid.h"
#include "fovea/shaders/grid_params.h"
#include "fovea/shaders/hash.h"
#include "fovea/shaders/live_cells.h"
#include "fovea/shaders/pt_order.h"
#include "fovea/shaders/grid_bindings.h"

layout(std140, set = 0, binding = GRID_BINDING_PARAMS) uniform Params { GridParams P; };
layout(std430, set = 0, binding = GRID_BINDING_COLUMNS) readonly buffer Columns { GridColumn cols[]; };
// Hidden view pixels (core::ViewMask): row-major, each row padded to whole 32-bit words.
layout(std430, set = 0, binding = GRID_BINDING_MASK) readonly buffer Mask { uint hidden_mask[]; };
layout(std430, set = 0, binding = GRID_BINDING_SAMPLES) writeonly buffer Samples { GridSample samples[]; };
// Zeroed by the host before the dispatch (gpu::GridPass::prepare).
layout(std430, set = 0, binding = GRID_BINDING_COUNTS) buffer Counts { GridCounts counts; };
layout(std430, set = 0, binding = GRID_BINDING_HISTORY) buffer History { uint history[]; };  // kLiveAllBefore
// Per tile: kTileLive | kTileReset; zero between frames (grid_live_list.comp clears it).
layout(std430, set = 0, binding = GRID_BINDING_TILE_STATE) buffer TileState { uint tile_state[]; };

#include "fovea/shaders/grid_map.glsl"

// Adds this subgroup's (without ballot: this invocation's) cells to the counts and to its
// tile's bits.
void count(bool live, bool reset, bool hidden, uint tile) {
#ifdef FOVEA_NO_BALLOT
  const uint n_live = live ? 1u : 0u, n_reset = reset ? 1u : 0u, n_hidden = hidden ? 1u : 0u;
#else
  const uint n_live = subgroupBallotBitCount(subgroupBallot(live));
  const uint n_reset = subgroupBallotBitCount(subgroupBallot(reset));
  const uint n_hidden = subgroupBallotBitCount(subgroupBallot(hidden));
  if (!subgroupElect()) return;
#endif
  if (n_live > 0u) atomicAdd(counts.live, n_live);
  if (n_reset > 0u) atomicAdd(counts.reset, n_reset);
  if (n_hidden > 0u) atomicAdd(counts.hidden, n_hidden);
  const uint bits = (n_live > 0u ? kTileLive : 0u) | (n_reset > 0u ? kTileReset : 0u);
  if (bits != 0u) atomicOr(tile_state[tile], bits);
}

void main() {
  // The grid is whole tiles (gpu::GridPass checks) and a workgroup one tile: every
  // invocation has a cell and takes part in its subgroup's ballots.
  const uint tile = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  const uint first = gl_WorkGroupID.y * kPtTileRows * P.padded_columns + gl_WorkGroupID.x * kPtTileColumns;
  const uint idx = live_tile_cell(first, gl_LocalInvocationIndex, P.padded_columns);
  vec2 centre;
  GridSample s = gm_sample(idx % P.padded_columns, idx / P.padded_columns, vec2(P.jitter_u, P.jitter_v), centre);
  if (s.flags == 0u && P.has_mask > 0.5) {
    // The view pixel containing the cell's centre, clamped into the raster (ViewMask::visible_at).
    uvec2 p = uvec2(clamp(centre, vec2(0.0), vec2(P.width - 1.0, P.height - 1.0)));
    uint words_per_row = (uint(P.width) + 31u) >> 5;
    if ((hidden_mask[p.y * words_per_row + (p.x >> 5)] & (1u << (p.x & 31u))) != 0u) s.flags |= kCellHidden;
  }
  samples[idx] = s;
  const bool live = s.flags == 0u;
  const uint before = history[idx];
  history[idx] = ((before << 1) | (live ? 1u : 0u)) & kLiveAllBefore;
  count(live, !live && before != 0u, s.flags == kCellHidden, tile);
}
