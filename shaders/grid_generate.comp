#version 460
// Grid generation: one GridSample (view direction, display position, flags) per cell of
// any sample distribution, from the per-frame GridParams and column table built by
// core::SampleDistribution on the CPU. Mirrors the CPU double-precision reference.
// Also counts the traced cells (flags 0) and the cells only the hidden-area mask skips, so
// nobody reads the grid back for them.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "fovea/shaders/grid.h"
#include "fovea/shaders/grid_params.h"
#include "fovea/shaders/hash.h"

layout(std140, set = 0, binding = 0) uniform Params { GridParams P; };
layout(std430, set = 0, binding = 1) readonly buffer Columns { GridColumn cols[]; };
// Hidden view pixels (core::ViewMask): row-major, each row padded to whole 32-bit words.
layout(std430, set = 0, binding = 2) readonly buffer Mask { uint hidden_mask[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Samples { GridSample samples[]; };
// Zeroed by the host before the dispatch (gpu::GridPass::prepare).
layout(std430, set = 0, binding = 4) buffer Counts { uint traced_cells; uint hidden_cells; };

#include "fovea/shaders/grid_map.glsl"

void main() {
  uvec2 cell = gl_GlobalInvocationID.xy;
  if (cell.x >= P.padded_columns || cell.y >= P.padded_rows) return;
  GridSample s = gm_sample(cell.x, cell.y, vec2(P.jitter_u, P.jitter_v));
  if (s.flags == 0u && P.has_mask > 0.5) {
    // The view pixel containing the sample, clamped into the raster (ViewMask::visible_at).
    uvec2 p = uvec2(clamp(vec2(s.screen_x, s.screen_y), vec2(0.0), vec2(P.width - 1.0, P.height - 1.0)));
    uint words_per_row = (uint(P.width) + 31u) >> 5;
    if ((hidden_mask[p.y * words_per_row + (p.x >> 5)] & (1u << (p.x & 31u))) != 0u) s.flags |= kCellHidden;
  }
  samples[cell.y * P.padded_columns + cell.x] = s;
  // One atomic per counted cell: a per-workgroup sum in shared memory needs two barriers,
  // which doubled this pass's time on lavapipe (fove0: 345 -> 703 ms).
  if (s.flags == 0u) atomicAdd(traced_cells, 1u);
  else if (s.flags == kCellHidden) atomicAdd(hidden_cells, 1u);
}
