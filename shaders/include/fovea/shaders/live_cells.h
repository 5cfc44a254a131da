// The live tiles of a sample grid (gpu::GridPass, docs/renderer.md "Live cells"): the grid
// pass lists the tiles of kPtTileColumns × kPtTileRows cells that hold a cell with a sample
// (flags 0), so that the per-cell kernels start a workgroup for those tiles alone, and after
// them the tiles without one that hold a "reset" cell: one without a sample
// this frame that had one in either of the two frames before. The reconstruction writes those
// once more, so that every per-cell buffer (double-buffered ones included) holds the empty
// values of a cell without a sample, and a tile that stays without samples is never
// dispatched again. A workgroup takes one tile (live_tile_cell). Shared C++/GLSL.
//
// The buffer: kLiveHeaderWords header words, then per entry the index of the tile's first
// cell (its top-left: row × columns + column), capacity one per tile: the live tiles, then
// the reset tiles, each in tile order (shaders/grid_live_list.comp). A cell index, so that
// lanes find their cell without an integer division.
#ifndef FOVEA_SHADERS_LIVE_CELLS_H
#define FOVEA_SHADERS_LIVE_CELLS_H
#include "fovea/shaders/common.h"
#include "fovea/shaders/pt_order.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

FOVEA_CONST FOVEA_UINT kLiveHeaderWords = 12u;
// Header words: a VkDispatchIndirectCommand for the live tiles (a workgroup each, folded into
// rows like gpu::ComputePipeline::dispatch_linear), their count, one for the live and reset
// tiles, the reset count and the grid's padded column count (words 9-11 unused: the entries
// start on a 16-byte boundary).
FOVEA_CONST FOVEA_UINT kLiveArgsLive = 0u;  // word offset of the live tiles' dispatch
FOVEA_CONST FOVEA_UINT kLiveCount = 3u;
FOVEA_CONST FOVEA_UINT kLiveArgsChanged = 4u;  // word offset of the live + reset tiles' dispatch
FOVEA_CONST FOVEA_UINT kLiveResetCount = 7u;
FOVEA_CONST FOVEA_UINT kLiveColumns = 8u;
FOVEA_CONST FOVEA_UINT kLiveTileCells = kPtTileColumns * kPtTileRows;  // = the kernels' workgroup size

// The grid pass's counters (host-visible, zeroed by the host before each frame).
struct GridCounts {
  FOVEA_UINT live;    // cells with a sample (flags 0)
  FOVEA_UINT hidden;  // cells only the hidden-area mask skipped (flags kCellHidden)
  FOVEA_UINT reset;   // cells without a sample now that had one in either frame before
  FOVEA_UINT tiles, tiles_across;  // the grid's (set by the host)
  FOVEA_UINT pad0, pad1, pad2;
};

// A tile's bits (grid_generate.comp's per-tile word, zero between frames): a live cell, a
// reset cell.
FOVEA_CONST FOVEA_UINT kTileLive = 1u;
FOVEA_CONST FOVEA_UINT kTileReset = 2u;

// A cell's liveness over the frames (the grid pass's per-cell history word): bit 0 this
// frame, bit 1 the frame before. New buffers start at kLiveAllBefore, so that every cell
// without a sample is reset in the first two frames.
FOVEA_CONST FOVEA_UINT kLiveAllBefore = 3u;

// The cell of lane l of the tile whose first cell is `first`, in a grid of `columns` columns
// (index = row * columns + column): down the tile's columns as in the tile order (a SIMD
// vector's cells are neighbours in φ on a polar grid). Along the rows instead (a vector's
// cells adjacent in memory), the reconstruction's kernels took 1.0–2.8× as long on lavapipe.
FOVEA_FN FOVEA_UINT live_tile_cell(FOVEA_UINT first, FOVEA_UINT l, FOVEA_UINT columns) {
  return first + (l % kPtTileRows) * columns + l / kPtTileRows;
}

// The first cell of tile t (row of tiles × tiles across + tile column).
FOVEA_FN FOVEA_UINT live_tile_first(FOVEA_UINT t, FOVEA_UINT tiles_across) {
  return (t / tiles_across) * kPtTileRows * tiles_across * kPtTileColumns + (t % tiles_across) * kPtTileColumns;
}

#ifdef __cplusplus
static_assert(sizeof(GridCounts) == 32);
}  // namespace fovea::shaders
#else
#ifdef LIVE_CELLS_LAYOUT
// A shader that reads the list defines LIVE_CELLS_LAYOUT as its layout qualifier. A storage
// buffer: every invocation of a workgroup reads the same words.
LIVE_CELLS_LAYOUT readonly buffer LiveList {
  uint live_header[kLiveHeaderWords];
  uint live_first[];
};

const uint kNoLiveCell = 0xFFFFFFFFu;

// The cell this invocation takes in an indirect dispatch from the header (one workgroup of
// kLiveTileCells per entry), or kNoLiveCell past the end: the live tiles, then with
// `with_reset` the reset ones. A cell without a sample in a listed tile is taken too.
uint live_cell(bool with_reset) {
  const uint n = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  uint entries = live_header[kLiveCount];
  if (with_reset) entries += live_header[kLiveResetCount];
  if (n >= entries) return kNoLiveCell;
  return live_tile_cell(live_first[n], gl_LocalInvocationIndex, live_header[kLiveColumns]);
}

// The cell this invocation of a per-cell kernel takes, or kNoLiveCell: with `listed` a cell of
// the live and reset tiles (an indirect dispatch from kLiveArgsChanged), else cell n of a
// dispatch_linear over all `cells`. After the shader's local_size declaration.
uint cell_of_invocation(uint cells, bool listed) {
  if (listed) return live_cell(true);
  const uint n = FOVEA_LINEAR_INVOCATION;
  return n < cells ? n : kNoLiveCell;
}
#endif
#endif
#endif
