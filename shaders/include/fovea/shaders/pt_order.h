// The path tracer's tile order (renderer::TraceOrder::Tiles; docs/renderer.md, "Trace
// order"): which grid cell invocation n traces. Shared C++/GLSL so the CPU (tests, the
// trace-cost benchmark) sees the SIMD vectors the shader forms.
//
// lavapipe runs a workgroup as SIMD vectors of consecutive local invocation indices (8 lanes
// with AVX2: llvmpipe's compute loop gives lane i of vector k the local index 8k + i). In grid
// order (invocation n traces cell n) a vector is 8 neighbouring columns of one grid row; on a
// Visual-Polar grid those are 8 rings at the same row index, whose φ differ because each ring
// has its own row count and arc start: on fove0 a vector's samples span 115 px of the display
// on average. In tile order the grid is cut into tiles of kPtTileColumns × kPtTileRows cells,
// one per 64-invocation workgroup, taken row by row over the grid; inside a tile, invocation l
// traces column l / kPtTileRows, row l % kPtTileRows, so a vector is 8 consecutive rows of one
// column: 8 neighbours in φ at one radius (11.5 px on fove0).
#ifndef FOVEA_SHADERS_PT_ORDER_H
#define FOVEA_SHADERS_PT_ORDER_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

FOVEA_CONST FOVEA_UINT kPtTileRows = 8u;     // one 8-lane vector down a column
FOVEA_CONST FOVEA_UINT kPtTileColumns = 8u;  // kPtTileRows × kPtTileColumns = pt_trace.comp's workgroup

// Cell of invocation n in a grid of `columns` columns (index = row * columns + column); both
// extents must be whole tiles, and then every cell has exactly one invocation.
FOVEA_FN FOVEA_UINT pt_tile_cell(FOVEA_UINT n, FOVEA_UINT columns) {
  const FOVEA_UINT tile = n / (kPtTileRows * kPtTileColumns), lane = n % (kPtTileRows * kPtTileColumns);
  const FOVEA_UINT tiles_across = columns / kPtTileColumns;
  const FOVEA_UINT row = (tile / tiles_across) * kPtTileRows + lane % kPtTileRows;
  const FOVEA_UINT column = (tile % tiles_across) * kPtTileColumns + lane / kPtTileRows;
  return row * columns + column;
}

#ifdef __cplusplus
}  // namespace fovea::shaders
#endif
#endif
