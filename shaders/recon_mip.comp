#version 460
// One level of the φ-only mip chain of a polar grid (P5 §3.4: minification happens only
// along φ near the gaze): cell r of level l+1 averages rows 2r and 2r+1 (wrapping on full
// rings; a packed column's last odd row pairs with itself) of level
// l, per column; a column of R rows has ceil(R / 2^l) rows at level l. Colours are
// premultiplied by coverage (.w), so cells without a sample never darken their neighbours.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers

layout(local_size_x = 8, local_size_y = 8) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(binding = RECON_TABLES) uniform textureBuffer tables;  // GridColumn: rg_table()
layout(std430, binding = RECON_MIP_MIPS) buffer Mips { vec4 mips[]; };

#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconMipPush pc; };

void main() {
  uvec2 cell = gl_GlobalInvocationID.xy;
  if (cell.x >= pc.padded_columns || cell.y >= pc.rows_out) return;
  ReconGrid m = maps[kReconCurrent];
  uint out_i = pc.offset_out + cell.y * pc.padded_columns + cell.x;
  uint full = cell.x < m.g.columns ? rg_rows(m, cell.x) : 0u;
  uint scale = 1u << pc.level_in;
  uint rows_in = (full + scale - 1u) / scale;
  uint rows_out = (rows_in + 1u) / 2u;
  if (cell.y >= rows_out) {
    mips[out_i] = vec4(0.0);
    return;
  }
  uint r0 = 2u * cell.y, r1 = rg_wraps(m, cell.x) ? (2u * cell.y + 1u) % rows_in : min(2u * cell.y + 1u, rows_in - 1u);
  mips[out_i] = 0.5 * (mips[pc.offset_in + r0 * pc.padded_columns + cell.x] + mips[pc.offset_in + r1 * pc.padded_columns + cell.x]);
}
