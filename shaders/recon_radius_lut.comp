#version 460
// Radius -> column lookup table of the current mapping, built per frame from its column
// table for the resolve (recon_map.h, rg_column_range). Bin k of `size` uniform bins over
// [0, r_max] (r_max: the last column's outer radius) holds lut[k] = the last column whose r0
// is <= (k - 0.5) / scale; entry size + 1 is the last column. A radius r in bin
// k = floor(r·scale) then lies in a column of [lut[k], lut[k + 2]]: the half-bin margins on
// both sides absorb the rounding of r·scale, so the narrowed search finds exactly the column
// the full binary search finds.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(binding = RECON_TABLES) uniform samplerBuffer tables;  // GridColumn: rg_table()
layout(std430, binding = RECON_LUT_OUT) writeonly buffer Lut {
  ReconRadiusLutHeader lut_header;
  uint lut[];  // kReconRadiusLutSize + 2 entries
};

#include "fovea/shaders/recon_map.h"

void main() {
  uint k = gl_GlobalInvocationID.x;
  const uint size = kReconRadiusLutSize;
  if (k >= size + 2u) return;
  ReconGrid m = maps[kReconCurrent];
  uint last = m.g.columns - 1u;
  float scale = float(size) / max(rg_table(m.table_offset + last).r1, 1e-6);
  if (k == 0u) lut_header = ReconRadiusLutHeader(scale, size, m.table_offset, 0u);
  lut[k] = k > size ? last : rg_column_of(m, (float(k) - 0.5) / scale, uvec2(0u, m.g.columns));
}
