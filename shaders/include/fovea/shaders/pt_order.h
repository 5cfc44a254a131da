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
// one per 64-invocation workgroup (which workgroup takes which tile: below); inside a tile,
// invocation l traces column l / kPtTileRows, row l % kPtTileRows, so a vector is 8
// consecutive rows of one column: 8 neighbours in φ at one radius (11.5 px on fove0).
#ifndef FOVEA_SHADERS_PT_ORDER_H
#define FOVEA_SHADERS_PT_ORDER_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
#include <bit>
#define PT_ORDER_LSB(x) FOVEA_UINT(std::countr_zero(x))
namespace fovea::shaders {
#else
#define PT_ORDER_LSB(x) uint(findLSB(x))
#endif

FOVEA_CONST FOVEA_UINT kPtTileRows = 8u;     // one 8-lane vector down a column
FOVEA_CONST FOVEA_UINT kPtTileColumns = 8u;  // kPtTileRows × kPtTileColumns = pt_trace.comp's workgroup

// Which tile workgroup w takes. llvmpipe hands each of its k threads one contiguous 1/k of a
// dispatch's workgroups (lp_cs_tpool.c: iter_per_thread = workgroups / threads), so taking
// tiles row by row gave the last thread the high rows, which on a polar grid are mostly the
// padding above the inner columns' last rows: that thread finished early and the other
// traced on alone (elapsed / CPU time of the trace on 2 threads 0.61, against 0.52 for a
// raster). Workgroup w takes tile (w % s) · (tiles / s) + w / s, s the largest power of two
// up to kPtTileStrips dividing the tile count (64 on fove0 and small): a thread's part takes
// the same share of each of s strips spread over the grid. s is the lowest set bit of the
// tile count (at most kPtTileStrips), so the map takes shifts and masks: lavapipe divides
// integers lane by lane: a loop of modulos here made primary rays 7–25% slower
// (fovea_bench_raytrace, docs/renderer.md).
FOVEA_CONST FOVEA_UINT kPtTileStrips = 1024u;

FOVEA_FN FOVEA_UINT pt_tile_of_workgroup(FOVEA_UINT w, FOVEA_UINT tiles) {
  const FOVEA_UINT low = tiles & (0u - tiles);
  const FOVEA_UINT s = low == 0u || low > kPtTileStrips ? kPtTileStrips : low, k = PT_ORDER_LSB(s);
  return (w & (s - 1u)) * (tiles >> k) + (w >> k);
}

// Cell of invocation n in a grid of `columns` columns and `cells` cells (index = row *
// columns + column); both extents must be whole tiles, and then every cell has exactly one
// invocation.
FOVEA_FN FOVEA_UINT pt_tile_cell(FOVEA_UINT n, FOVEA_UINT columns, FOVEA_UINT cells) {
  const FOVEA_UINT per_tile = kPtTileRows * kPtTileColumns;
  const FOVEA_UINT tile = pt_tile_of_workgroup(n / per_tile, cells / per_tile), lane = n % per_tile;
  const FOVEA_UINT tiles_across = columns / kPtTileColumns;
  const FOVEA_UINT row = (tile / tiles_across) * kPtTileRows + lane % kPtTileRows;
  const FOVEA_UINT column = (tile % tiles_across) * kPtTileColumns + lane / kPtTileRows;
  return row * columns + column;
}

#ifdef __cplusplus
}  // namespace fovea::shaders
#endif
#endif
