#version 460
// The live-tile list (live_cells.h) from grid_generate.comp's per-tile bits, in tile order:
// the tiles with a live cell, then those without one that hold a reset cell; then the header,
// with the indirect dispatches (a workgroup per tile, folded into rows of at most max_groups_x
// as evenly as the rounding allows, like gpu::ComputePipeline::dispatch_linear). Clears the
// bits for the next frame. One workgroup; each invocation takes a contiguous part of the
// tiles. In tile order, not in the order the tiles finished (an atomic append): the list is
// the same from run to run, and a contiguous part of it (what llvmpipe gives one thread) is
// one region of the grid.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 256) in;

#include "fovea/shaders/live_cells.h"
#include "fovea/shaders/grid_bindings.h"

layout(std430, set = 0, binding = LIVE_LIST_BINDING_COUNTS) readonly buffer Counts { GridCounts counts; };
layout(std430, set = 0, binding = LIVE_LIST_BINDING_LIST) writeonly buffer List { uint header[kLiveHeaderWords]; uint list[]; };
layout(std430, set = 0, binding = LIVE_LIST_BINDING_TILE_STATE) buffer TileState { uint tile_state[]; };
layout(push_constant) uniform Push { uint max_groups_x; };

shared uint s_live[gl_WorkGroupSize.x], s_reset[gl_WorkGroupSize.x];

void write_args(uint at, uint groups) {
  const uint rows = max(1u, (groups + max_groups_x - 1u) / max_groups_x);
  header[at] = (groups + rows - 1u) / rows;
  header[at + 1u] = groups == 0u ? 0u : rows;
  header[at + 2u] = 1u;
}

void main() {
  const uint l = gl_LocalInvocationIndex, n = gl_WorkGroupSize.x;
  const uint per = (counts.tiles + n - 1u) / n;
  const uint first = min(l * per, counts.tiles), last = min(first + per, counts.tiles);
  uint live = 0u, reset = 0u;
  for (uint t = first; t < last; ++t) {
    const uint s = tile_state[t];
    live += (s & kTileLive) != 0u ? 1u : 0u;
    reset += s == kTileReset ? 1u : 0u;
  }
  s_live[l] = live;
  s_reset[l] = reset;
  barrier();
  uint live_before = 0u, reset_before = 0u, live_all = 0u, reset_all = 0u;
  for (uint k = 0u; k < n; ++k) {
    live_before += k < l ? s_live[k] : 0u;
    reset_before += k < l ? s_reset[k] : 0u;
    live_all += s_live[k];
    reset_all += s_reset[k];
  }
  for (uint t = first; t < last; ++t) {
    const uint s = tile_state[t];
    if ((s & kTileLive) != 0u) list[live_before++] = live_tile_first(t, counts.tiles_across);
    else if (s == kTileReset) list[live_all + reset_before++] = live_tile_first(t, counts.tiles_across);
    tile_state[t] = 0u;
  }
  if (l == 0u) {
    write_args(kLiveArgsLive, live_all);
    header[kLiveCount] = live_all;
    write_args(kLiveArgsChanged, live_all + reset_all);
    header[kLiveResetCount] = reset_all;
    header[kLiveColumns] = counts.tiles_across * kPtTileColumns;
  }
}
