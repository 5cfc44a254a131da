#version 460
// Peripheral blur in grid space (angular Visual-Polar; docs/reconstruction.md): one pass of a
// separable Gaussian over the grid image (premultiplied colour, .w coverage) before the
// φ-mip chain. σ(e) degrees from the acuity model (as recon_blur.comp) is converted to cells
// with the column's own cell size: its width in eccentricity (ρ pass, across columns) or its
// row height 360°·sin e·arc / rows (φ pass, along the column). Cells and σ both follow the
// eccentricity, so the kernel is a few cells wide at most, where on the display it reaches
// many pixels; cells whose σ is below min_sigma_cells are copied (the grid cannot carry a
// sub-cell blur; the resample's bilinear reconstruction is already a cell wide), unless the
// cell spans several display pixels in the pass's direction: then σ is at least
// lattice_sigma_cells, faded in from kReconLatticeFromPx to kReconLatticeFullPx pixels, so
// that the reconstruction reaches beyond the cell and its lattice (rings, spokes) does not show.
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

// Display pixels per degree at the centre of a cell at eccentricity e_deg and grid coordinate
// t (φ / 2π from the basis b1): the mean of a pixel's angular width and height there. A cell
// whose centre is not in front of the eye counts as having no pixels.
float cell_pixels_per_deg(ReconGrid m, float e_deg, float t) {
  float e = e_deg * (kRgPi / 180.0), phi = 2.0 * kRgPi * t;
  vec3 d = cos(e) * rg_gaze(m) + sin(e) * (cos(phi) * vec3(m.g.b1_x, m.g.b1_y, m.g.b1_z) +
                                          sin(phi) * vec3(m.g.b2_x, m.g.b2_y, m.g.b2_z));
  if (!(d.z < -1e-6)) return 0.0;
  vec2 tan_xy = d.xy / -d.z;
  float pixel_rad = 0.5 * (rg_pixel_angle(m, tan_xy, false) + rg_pixel_angle(m, tan_xy, true));
  return (kRgPi / 180.0) / max(pixel_rad, 1e-12);
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
  float lattice = 0.0;  // the lattice's blur (off unless asked for): its weight, by the cell's pixels
  if (pc.lattice_sigma_cells > 0.0 && e >= pc.lattice_min_deg) {
    float px = cell_deg * cell_pixels_per_deg(m, e, rg_row_to_t_of(col, float(r) + 0.5));
    lattice = smoothstep(kReconLatticeFromPx, kReconLatticeFullPx, px);
  }
  bool acuity = sigma >= pc.min_sigma_cells;
  if (!acuity && !(lattice > 0.0)) {
    dst[i] = own;
    return;
  }
  if (lattice > 0.0) sigma = max(sigma, pc.lattice_sigma_cells);
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
  // Where only the lattice asks for it, the blur fades in with the cell's size in pixels.
  dst[i] = acuity ? acc / wsum : mix(own, acc / wsum, lattice);
}
