// The live-cell list of a sample grid (gpu::GridPass, docs/renderer.md "Live cells"): the
// grid pass lists the cells it gives a sample (flags 0), so that the per-cell kernels start a
// thread for those alone, and, from the back of the list, the cells it gave none this frame
// though it gave them one in either of the two frames before ("reset" cells): the
// reconstruction writes those once more, so that every per-cell buffer (double-buffered ones
// included) holds the empty values of a cell without a sample, and a cell that stays without
// one is never dispatched again. Shared C++/GLSL.
//
// The buffer: kLiveHeaderWords header words, then one cell index per list entry (capacity:
// the grid's cells). Live entries from the front, in tile order (pt_order.h: each run of
// kPtTileRows entries one column of a tile, down the rows, as far as its cells are live);
// the reset entries from the back (entry k at header + capacity - 1 - k).
#ifndef FOVEA_SHADERS_LIVE_CELLS_H
#define FOVEA_SHADERS_LIVE_CELLS_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

FOVEA_CONST FOVEA_UINT kLiveHeaderWords = 8u;
// Header words: a VkDispatchIndirectCommand for the live cells, their count, one for the
// live and reset cells, the reset count. The dispatches are for workgroups of
// kLiveGroupSize invocations, folded into rows like gpu::ComputePipeline::dispatch_linear.
FOVEA_CONST FOVEA_UINT kLiveArgsLive = 0u;      // word offset of the live cells' dispatch
FOVEA_CONST FOVEA_UINT kLiveCount = 3u;
FOVEA_CONST FOVEA_UINT kLiveArgsChanged = 4u;   // word offset of the live + reset cells' dispatch
FOVEA_CONST FOVEA_UINT kLiveResetCount = 7u;
FOVEA_CONST FOVEA_UINT kLiveGroupSize = 64u;

// The grid pass's counters (host-visible, zeroed by the host before each frame).
struct GridCounts {
  FOVEA_UINT live;    // cells with a sample (flags 0)
  FOVEA_UINT hidden;  // cells only the hidden-area mask skipped (flags kCellHidden)
  FOVEA_UINT reset;   // cells without a sample now that had one in either frame before
  FOVEA_UINT pad;
};

// A cell's liveness over the frames (the grid pass's per-cell history word): bit 0 this
// frame, bit 1 the frame before. New buffers start at kLiveAllBefore, so that every cell
// without a sample is reset in the first two frames.
FOVEA_CONST FOVEA_UINT kLiveAllBefore = 3u;

#ifdef __cplusplus
static_assert(sizeof(GridCounts) == 16);
}  // namespace fovea::shaders
#else
#ifdef LIVE_CELLS_LAYOUT
// A shader that reads the list defines LIVE_CELLS_LAYOUT as its layout qualifier. A texel
// buffer (R32_UINT): lavapipe fetches texels as one gather (docs/gpu.md, "Texel buffers").
LIVE_CELLS_LAYOUT uniform utextureBuffer live_list;

const uint kNoLiveCell = 0xFFFFFFFFu;

// The cell of list entry n (FOVEA_LINEAR_INVOCATION of an indirect dispatch from the
// header), or kNoLiveCell past the end: the live cells, then with `with_reset` the reset
// ones. `capacity`: the grid's cells.
uint live_cell(uint n, uint capacity, bool with_reset) {
  const uint live = texelFetch(live_list, int(kLiveCount)).x;
  if (n < live) return texelFetch(live_list, int(kLiveHeaderWords + n)).x;
  n -= live;
  if (!with_reset || n >= texelFetch(live_list, int(kLiveResetCount)).x) return kNoLiveCell;
  return texelFetch(live_list, int(kLiveHeaderWords + capacity - 1u - n)).x;
}

// The cell this invocation of a per-cell kernel takes, or kNoLiveCell: with `listed` the
// list's live cells, then its reset ones (an indirect dispatch from kLiveArgsChanged), else
// cell n of a dispatch_linear over all `cells`. After the shader's local_size declaration.
uint cell_of_invocation(uint cells, bool listed) {
  const uint n = FOVEA_LINEAR_INVOCATION;
  if (listed) return live_cell(n, cells, true);
  return n < cells ? n : kNoLiveCell;
}
#endif
#endif
#endif
