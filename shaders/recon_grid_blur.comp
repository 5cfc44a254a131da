#version 460
// Peripheral blur in grid space (angular Visual-Polar; docs/reconstruction.md): one pass of a
// separable Gaussian over the grid image (premultiplied colour, .w coverage) before the
// φ-mip chain. σ(e) degrees from the acuity model (as recon_blur.comp) is converted to cells
// with the column's own cell size: its width in eccentricity (ρ pass, across columns) or its
// row height 360°·sin e·arc / rows (φ pass, along the column). Cells and σ both follow the
// eccentricity, so the kernel is a few cells wide at most, where on the display it reaches
// many pixels; cells whose σ is below min_sigma_cells are copied (the grid cannot carry a
// sub-cell blur; the resample's reconstruction is already a cell wide).
// The ρ pass reads each neighbouring column at the cell's φ (rows differ per column),
// linearly between its two rows there; φ wraps on full rings, clamps at a packed column's
// ends and at the grid's first/last column (weights renormalised).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers

layout(local_size_x = 8, local_size_y = 8) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(binding = RECON_TABLES) uniform textureBuffer tables;  // GridColumn: rg_table()
layout(binding = RECON_BLUR_SRC) uniform textureBuffer src;
layout(std430, binding = RECON_BLUR_DST) writeonly buffer Dst { vec4 dst[]; };

#include "fovea/shaders/recon_map.h"
#include "fovea/shaders/recon_blur.h"

layout(push_constant) uniform Push { ReconGridBlurPush pc; };

// Column cc of m at grid coordinate t: linear between its two rows around t's row coordinate
// (the column's table entry read once).
vec4 column_at(ReconGrid m, uint cc, float t) {
  GridColumn col = rg_column(m, cc);
  int r0, r1;
  float f;
  rg_row_pair(int(max(col.rows, 1u)), col.phi_gap == 0.0, rg_row_coord_of(col, t), r0, r1, f);
  uint pcols = m.g.padded_columns;
  return (1.0 - f) * texelFetch(src, int(uint(r0) * pcols + cc)) + f * texelFetch(src, int(uint(r1) * pcols + cc));
}

void main() {
  ReconGrid m = maps[kReconCurrent];
  uint c = pc.first_column + gl_GlobalInvocationID.x, r = gl_GlobalInvocationID.y;
  if (c >= m.g.columns || r >= m.g.padded_rows) return;
  uint i = r * m.g.padded_columns + c;
  GridColumn col = rg_table(m.table_offset + c);
  if (r >= col.rows) return;  // beyond the column's rows: no kernel reads these cells
  vec4 own = texelFetch(src, int(i));
  if (!(own.w > 0.0)) {  // no sample (the lens' hidden area, off the view): it stays without one
    dst[i] = own;
    return;
  }
  bool phi_pass = pc.phi_pass != 0u;
  float e = 0.5 * (col.r0 + col.r1);
  float arc = 1.0 - col.phi_gap / (2.0 * kRgPi);
  float cell_deg = phi_pass ? 360.0 * sin(e * (kRgPi / 180.0)) * arc / float(col.rows) : col.r1 - col.r0;
  float sigma = min(rg_blur_sigma_deg(e, pc.sigma_fovea_deg) / max(cell_deg, 1e-6), pc.max_sigma_cells);
  if (sigma < pc.min_sigma_cells) {
    dst[i] = own;
    return;
  }
  int radius = int(ceil(3.0 * sigma));
  // Weights exp(a k²), a = -1/(2σ²), by the recurrence of recon_blur.comp.
  float a = -0.5 / (sigma * sigma);
  float w = 1.0, q = exp(a), q2 = q * q;
  vec4 acc = own;
  float wsum = 1.0;
  if (phi_pass) {
    int rows = int(col.rows);
    bool wraps = col.phi_gap == 0.0;
    if (wraps) radius = min(radius, rows);  // a kernel around the whole ring: one wrap at most
    for (int k = 1; k <= radius; ++k) {
      w *= q;
      q *= q2;
      for (int s = -1; s <= 1; s += 2) {
        int rr = int(r) + s * k;
        if (wraps) rr += rr < 0 ? rows : (rr >= rows ? -rows : 0);
        else if (rr < 0 || rr >= rows) continue;
        acc += w * texelFetch(src, int(uint(rr) * m.g.padded_columns + c));
        wsum += w;
      }
    }
  } else {
    float t = rg_row_to_t_of(col, float(r) + 0.5);
    for (int k = 1; k <= radius; ++k) {
      w *= q;
      q *= q2;
      for (int s = -1; s <= 1; s += 2) {
        int cc = int(c) + s * k;
        if (cc < 0 || cc >= int(m.g.columns)) continue;
        acc += w * column_at(m, uint(cc), t);
        wsum += w;
      }
    }
  }
  dst[i] = acc / wsum;
}
