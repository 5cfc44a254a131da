#version 460
// Grid generation: one GridSample (view direction, display position, flags) per cell of
// any sample distribution, from the per-frame GridParams and column table built by
// core::SampleDistribution on the CPU. Mirrors the CPU double-precision reference.
// Also counts the traced cells (flags 0) and the cells only the hidden-area mask skips, so
// nobody reads the grid back for them, and lists the live and reset cells (live_cells.h).
//
// One workgroup per tile of kPtTileColumns × kPtTileRows cells; invocation l takes column
// l / kPtTileRows, row l % kPtTileRows of its tile, so a subgroup is one or more whole tile
// columns and the list keeps a column's live cells next to each other, down its rows (the
// trace's coherent order, pt_order.h). Each subgroup appends its cells with one atomic
// (ballot): one per cell made this pass 2× slower on lavapipe than one per subgroup, and a
// workgroup-wide sum in shared memory needs barriers, which doubled it again (fove0: 345 ->
// 703 ms). FOVEA_NO_BALLOT (devices without subgroup ballot): one atomic per listed cell.
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

layout(std140, set = 0, binding = 0) uniform Params { GridParams P; };
layout(std430, set = 0, binding = 1) readonly buffer Columns { GridColumn cols[]; };
// Hidden view pixels (core::ViewMask): row-major, each row padded to whole 32-bit words.
layout(std430, set = 0, binding = 2) readonly buffer Mask { uint hidden_mask[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Samples { GridSample samples[]; };
// Zeroed by the host before the dispatch (gpu::GridPass::prepare).
layout(std430, set = 0, binding = 4) buffer Counts { GridCounts counts; };
layout(std430, set = 0, binding = 5) writeonly buffer List { uint header[kLiveHeaderWords]; uint list[]; };
layout(std430, set = 0, binding = 6) buffer History { uint history[]; };  // kLiveAllBefore

#include "fovea/shaders/grid_map.glsl"

// The first of `n` entries this invocation's subgroup (or, without ballot, this invocation)
// takes in a list whose length is `counter`; `mine`: this invocation takes one.
#ifdef FOVEA_NO_BALLOT
#define APPEND(counter, mine, slot) \
  if (mine) slot = atomicAdd(counter, 1u);
#else
#define APPEND(counter, mine, slot)                                          \
  {                                                                          \
    const uvec4 b = subgroupBallot(mine);                                    \
    const uint n = subgroupBallotBitCount(b);                                \
    uint first = 0u;                                                         \
    if (n > 0u && subgroupElect()) first = atomicAdd(counter, n);            \
    slot = subgroupBroadcastFirst(first) + subgroupBallotExclusiveBitCount(b); \
  }
#endif

void main() {
  const uint l = gl_LocalInvocationIndex;
  const uvec2 cell = uvec2(gl_WorkGroupID.x * kPtTileColumns + l / kPtTileRows,
                           gl_WorkGroupID.y * kPtTileRows + l % kPtTileRows);
  // No early return: every invocation takes part in its subgroup's ballots.
  const bool inside = cell.x < P.padded_columns && cell.y < P.padded_rows;
  const uint idx = cell.y * P.padded_columns + cell.x;
  uint flags = kCellPadding;
  if (inside) {
    GridSample s = gm_sample(cell.x, cell.y, vec2(P.jitter_u, P.jitter_v));
    if (s.flags == 0u && P.has_mask > 0.5) {
      // The view pixel containing the sample, clamped into the raster (ViewMask::visible_at).
      uvec2 p = uvec2(clamp(vec2(s.screen_x, s.screen_y), vec2(0.0), vec2(P.width - 1.0, P.height - 1.0)));
      uint words_per_row = (uint(P.width) + 31u) >> 5;
      if ((hidden_mask[p.y * words_per_row + (p.x >> 5)] & (1u << (p.x & 31u))) != 0u) s.flags |= kCellHidden;
    }
    samples[idx] = s;
    flags = s.flags;
  }
  const bool live = inside && flags == 0u;
  const uint before = inside ? history[idx] : 0u;
  if (inside) history[idx] = ((before << 1) | (live ? 1u : 0u)) & kLiveAllBefore;
  const bool reset = inside && !live && before != 0u;
  uint slot = 0u;
  APPEND(counts.live, live, slot)
  if (live) list[slot] = idx;
  APPEND(counts.reset, reset, slot)
  if (reset) list[P.padded_columns * P.padded_rows - 1u - slot] = idx;
  APPEND(counts.hidden, inside && flags == kCellHidden, slot)
}
