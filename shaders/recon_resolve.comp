#version 460
// Resolve to the display (P5 §3.4): every display pixel computes its grid coordinate through
// the current mapping (the column found through the mapping's radius lookup table,
// recon_map.h) and samples the grid — trilinear over the φ-only mip chain
// (bilinear in ρ between the two columns, each with its own row count; φ wraps, ρ clamps).
// The level comes from the pixel's footprint along φ in rows of its column (analytic). The
// same grid coordinate gives the display-space depth, when asked for (push constant depth): the
// nearest cell's sample's view-space distance along -Z (no filtering: depths must not blend
// across silhouettes), 0 where that cell saw the sky or holds no sample; for depth
// compositing, the image does not use it. Near the gaze, where the path tracer's first hits
// at the display's pixels are given (pt_primary.h), textures are re-modulated at the display's
// resolution (detail_gain). With the lattice's reconstruction on, cells several pixels wide
// are reconstructed with the cubic B-spline instead of the tent (lattice_weights); the
// Cartesian raster with its Gaussian filter on, each pixel over its 3×3 cells (raster_gaussian).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require  // texelFetch on texture buffers

layout(local_size_x = 8, local_size_y = 8) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/recon_grid.h"
#include "fovea/shaders/pt_trace.h"  // kPtMinDemodAlbedo

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(binding = RECON_TABLES) uniform textureBuffer tables;  // GridColumn: rg_table()
layout(binding = RECON_RESOLVE_MIPS) uniform textureBuffer mips;
layout(std430, binding = RECON_RESOLVE_OFFSETS) readonly buffer Offsets { uint level_offset[]; };
layout(std430, binding = RECON_RESOLVE_SCREEN) writeonly buffer Screen { vec4 screen[]; };
layout(binding = RECON_RESOLVE_POS) uniform textureBuffer vpos;  // world position, .w material code
layout(std430, binding = RECON_RESOLVE_DEPTH) writeonly buffer Depth { float depth[]; };
layout(binding = RECON_RESOLVE_LUTS) uniform utextureBuffer radius_luts;
layout(binding = RECON_RESOLVE_ALBEDO) uniform textureBuffer cell_albedo;
layout(binding = RECON_RESOLVE_PRIMARY) uniform textureBuffer primary;

#define RG_RADIUS_LUT
#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconResolvePush pc; };

// One column of the bilinear pair: its table entry is read once per pixel, and every level
// and the depth reuse its rows, wrap and level-0 row coordinate.
struct ColumnTap {
  uint c;
  int rows;
  bool wraps;       // full ring: rows wrap (r0 in [-1, rows), r1 in [0, rows]); else clamp
  float v;          // row coordinate of the pixel's φ at level 0 (cell centres at +0.5)
  float turn_rows;  // rows over a full turn at the column's spacing (the LOD's unit)
  float width;      // r1 - r0: degrees (angular polar) or pixels (screen polar)
};

ColumnTap column_tap(ReconGrid m, int ci, float t) {
  ColumnTap k;
  k.c = uint(clamp(ci, 0, int(m.g.columns) - 1));
  GridColumn col = rg_column(m, k.c);
  k.rows = int(max(col.rows, 1u));
  k.wraps = rg_column_wraps(m, col);
  k.v = rg_row_coord_of(col, t);
  k.turn_rows = float(col.rows) / (1.0 - col.phi_gap / (2.0 * kRgPi));
  k.width = col.r1 - col.r0;
  return k;
}

// Linear in φ between the two rows of column k at level `level`.
vec4 fetch_column(ColumnTap k, uint level, uint base, uint pcols) {
  int r0, r1;
  float fy;
  rg_row_pair((k.rows + (1 << level) - 1) >> level, k.wraps, k.v / float(1u << level), r0, r1, fy);
  return (1.0 - fy) * texelFetch(mips, int(base + uint(r0) * pcols + k.c)) +
         fy * texelFetch(mips, int(base + uint(r1) * pcols + k.c));
}

// Bilinear at level `level` of the column pair (bilinear in ρ between two columns of
// different row counts, each at its own row coordinate of the same φ).
vec4 fetch_level(ReconGrid m, ColumnTap k0, ColumnTap k1, float fx, uint level) {
  uint base = level_offset[level];
  return (1.0 - fx) * fetch_column(k0, level, base, m.g.padded_columns) + fx * fetch_column(k1, level, base, m.g.padded_columns);
}

// Weights of the four samples around x in [0, 1) between the middle two: the tent's (0, 1-x,
// x, 0) blended with the uniform cubic B-spline's by `smooth` (0..1). The B-spline is C2
// across the samples, so the reconstruction has no kinks at the cell centres, whose Mach
// bands show the lattice (rings about the gaze, spokes) where a cell spans several pixels.
vec4 lattice_weights(float x, float smooth_) {
  float y = 1.0 - x, x2 = x * x, x3 = x2 * x;
  vec4 b = vec4(y * y * y, 3.0 * x3 - 6.0 * x2 + 4.0, -3.0 * x3 + 3.0 * x2 + 3.0 * x + 1.0, x3) / 6.0;
  return mix(vec4(0.0, y, x, 0.0), b, smooth_);
}

// Column k at level 0 (at the buffer's start) over four rows around its row coordinate
// (lattice_weights along φ); `tent_w`: the coverage (.w) the tent's two rows give.
vec4 fetch_column_smooth(ColumnTap k, uint pcols, float smooth_, out float tent_w) {
  if (!(smooth_ > 0.0)) {
    vec4 v = fetch_column(k, 0u, 0u, pcols);
    tent_w = v.w;
    return v;
  }
  int r0, r1;
  float fy;
  rg_row_pair(k.rows, k.wraps, k.v, r0, r1, fy);
  vec4 w = lattice_weights(fy, smooth_);
  int rm = rg_row_index(r0 - 1, k.rows, k.wraps), rp = rg_row_index(r1 + 1, k.rows, k.wraps);
  vec4 a = texelFetch(mips, int(uint(r0) * pcols + k.c)), b = texelFetch(mips, int(uint(r1) * pcols + k.c));
  tent_w = (1.0 - fy) * a.w + fy * b.w;
  return w.x * texelFetch(mips, int(uint(rm) * pcols + k.c)) + w.y * a + w.z * b +
         w.w * texelFetch(mips, int(uint(rp) * pcols + k.c));
}

// The Cartesian raster's Gaussian reconstruction (pc.raster_side > 0): the cells around cell
// (c, r) weighed per axis by side, 1 − 2·side, side; cells beyond the raster drop out and the
// weights renormalise. Summed as the tent's taps are (coverage in .w), so a cell without a
// sample (the lens' hidden area) adds nothing, and a pixel whose own cell has none stays
// without one.
vec4 raster_gaussian(ReconGrid m, int c, int r) {
  if (!(texelFetch(mips, int(uint(r) * m.g.padded_columns + uint(c))).w > 1e-6)) return vec4(0.0);
  vec4 acc = vec4(0.0);
  float wsum = 0.0;
  for (int dr = -1; dr <= 1; ++dr) {
    int rr = r + dr;
    if (rr < 0 || rr >= int(m.g.rows)) continue;
    float wr = dr == 0 ? 1.0 - 2.0 * pc.raster_side : pc.raster_side;
    for (int dc = -1; dc <= 1; ++dc) {
      int cc = c + dc;
      if (cc < 0 || cc >= int(m.g.columns)) continue;
      float w = wr * (dc == 0 ? 1.0 - 2.0 * pc.raster_side : pc.raster_side);
      acc += w * texelFetch(mips, int(uint(rr) * m.g.padded_columns + uint(cc)));
      wsum += w;
    }
  }
  return acc / wsum;
}

// The pixel's angular size δ on angular polar grids (the larger of its two sides, radians),
// else 1 (screen polar grids measure radii in pixels).
float pixel_delta(ReconGrid m, vec2 t) {
  return m.g.family == kFamilyAngularPolar ? max(rg_pixel_angle(m, t, false), rg_pixel_angle(m, t, true)) : 1.0;
}

// Footprint of the pixel along φ in rows of its column (turn_rows; the LOD's argument): a
// pixel of angular size δ (pixel_delta) at eccentricity e spans δ / (2π sin e) of the circle
// (angular polar); at radius r one pixel spans 1 / (2π r) (screen polar).
float phi_footprint(ReconGrid m, float delta, vec3 d, vec2 px, float turn_rows) {
  if (m.g.family == kFamilyAngularPolar)
    return delta * turn_rows / (2.0 * kRgPi * max(length(cross(d, rg_gaze(m))), 1e-6));
  float r = length(px - vec2(m.g.gaze_px_x, m.g.gaze_px_y));
  return turn_rows / (2.0 * kRgPi * max(r, 1e-6));
}

// The factor that re-modulates a pixel's colour with its own first hit's base colour instead
// of its cells' albedo (the one their output holds: TAA's re-modulation albedo, blended with
// the history's as the colour is, interpolated by the colour's level-0 weights): the cells'
// box filter of the texture, which the tent between cells blurs once more, gives way to the
// pixel's own texture, where the grid's cells are about a pixel and polar cells are not the
// display's pixels (docs/reconstruction.md, "Textures at the display's resolution"). Only
// where the pixel and every weighted cell saw a surface (never at an emitter or the sky, whose
// light no albedo scales), fading out from detail_cos_full to detail_cos_none, and at most
// kReconDetailMaxGain either way. Across a silhouette between surfaces the pixel's own albedo
// scales the cells' light: requiring one material there switched the gain on and off with the
// cells' jitter from frame to frame.
vec3 detail_gain(ReconGrid m, ColumnTap k0, ColumnTap k1, float fx, uvec2 p, vec3 d) {
  uvec2 q = p - uvec2(pc.detail_x0, pc.detail_y0);  // wraps above the window's corner
  if (q.x >= pc.detail_width || q.y >= pc.detail_height) return vec3(1.0);
  float fade = smoothstep(pc.detail_cos_none, pc.detail_cos_full, dot(d, rg_gaze(m)));
  vec4 hit = texelFetch(primary, int(q.y * pc.detail_width + q.x));
  if (fade <= 0.0 || hit.w < 0.0) return vec3(1.0);
  vec4 a = vec4(0.0);
  for (int side = 0; side < 2; ++side) {
    ColumnTap k = side == 0 ? k0 : k1;
    int r0, r1;
    float fy;
    rg_row_pair(k.rows, k.wraps, k.v, r0, r1, fy);
    for (int t = 0; t < 2; ++t) {
      float w = (side == 0 ? 1.0 - fx : fx) * (t == 0 ? 1.0 - fy : fy);
      int j = int(uint(t == 0 ? r0 : r1) * m.g.padded_columns + k.c);
      if (w <= 0.0 || texelFetch(mips, j).w <= 0.0) continue;  // no weight, or no sample (level 0)
      if (texelFetch(vpos, j).w < 0.0) return vec3(1.0);  // the sky or an emitter
      a += w * vec4(texelFetch(cell_albedo, j).rgb, 1.0);
    }
  }
  if (!(a.w > 0.0)) return vec3(1.0);
  vec3 gain = max(hit.rgb, vec3(kPtMinDemodAlbedo)) / max(a.rgb / a.w, vec3(kPtMinDemodAlbedo));
  return mix(vec3(1.0), clamp(gain, vec3(1.0 / kReconDetailMaxGain), vec3(kReconDetailMaxGain)), fade);
}

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  ReconGrid m = maps[kReconCurrent];
  vec2 px = vec2(p) + 0.5;
  bool polar = m.g.family != kFamilyCartesian;
  vec2 t = rg_pixel_tan(m, px);
  vec3 d = normalize(vec3(t, -1.0));
  vec2 uv = rg_grid_coord(m, d, px);
  float uc = uv.x - 0.5;
  float c0f = floor(uc);
  float fx = uc - c0f;
  ColumnTap k0 = column_tap(m, int(c0f), uv.y), k1 = column_tap(m, int(c0f) + 1, uv.y);
  ColumnTap near = fx >= 0.5 ? k1 : k0;  // the column of floor(u), clamped
  float lod = 0.0;
  if (pc.levels > 1u && polar && near.c < pc.lod_columns) {
    float footprint = phi_footprint(m, pixel_delta(m, t), d, px, near.turn_rows);
    lod = clamp(log2(max(footprint, 1.0)), 0.0, float(pc.levels - 1u));
  }
  uint i = p.y * pc.width + p.x;
  if (pc.grid_coords != 0u) {
    screen[i] = vec4(uv, lod, 0.0);
    return;
  }
  uint l0 = uint(floor(lod));
  float f = lod - float(l0);
  // The lattice's reconstruction (--lattice-blur on, recon_grid.h): where a cell spans more
  // than kReconLatticeFromPx display pixels in a direction (fully from kReconLatticeFullPx),
  // the cubic B-spline across four cells in that direction instead of the tent; not within
  // the display pixels' albedo window, whose gain divides by the tent-weighted cells' albedo.
  // A cell's pixels: its width over the pixel's size δ, and one over its rows per pixel.
  float lat_rho = 0.0, lat_phi = 0.0;
  if (pc.lattice != 0u && polar && lod == 0.0 &&
      !(pc.detail_width > 0u && dot(d, rg_gaze(m)) > pc.detail_cos_none)) {
    float delta = pixel_delta(m, t);
    float unit = m.g.family == kFamilyAngularPolar ? delta * (180.0 / kRgPi) : 1.0;  // degrees or pixels
    lat_rho = smoothstep(kReconLatticeFromPx, kReconLatticeFullPx, near.width / unit);
    lat_phi = smoothstep(kReconLatticeFromPx, kReconLatticeFullPx,
                         1.0 / max(phi_footprint(m, delta, d, px, near.turn_rows), 1e-6));
  }
  vec4 v;
  if (!polar && pc.raster_side > 0.0) {
    v = raster_gaussian(m, int(near.c), int(floor(near.v)));
  } else if (lat_rho > 0.0 || lat_phi > 0.0) {
    vec4 w = lattice_weights(fx, lat_rho);
    uint pcols = m.g.padded_columns;
    float t0, t1, unused;
    v = w.y * fetch_column_smooth(k0, pcols, lat_phi, t0) + w.z * fetch_column_smooth(k1, pcols, lat_phi, t1);
    if (w.x > 0.0) v += w.x * fetch_column_smooth(column_tap(m, int(c0f) - 1, uv.y), pcols, lat_phi, unused);
    if (w.w > 0.0) v += w.w * fetch_column_smooth(column_tap(m, int(c0f) + 2, uv.y), pcols, lat_phi, unused);
    // Coverage as the tent's: a pixel whose two nearest cells in each direction hold no sample
    // (the lens' hidden area, off the view) stays without one, however far the spline reaches.
    if (!((1.0 - fx) * t0 + fx * t1 > 1e-6)) v = vec4(0.0);
  } else {
    v = fetch_level(m, k0, k1, fx, l0);
    if (f > 0.0 && l0 + 1u < pc.levels) v = mix(v, fetch_level(m, k0, k1, fx, l0 + 1u), f);
  }
  vec3 colour = v.w > 1e-6 ? v.rgb / v.w : vec3(0.0);
  if (pc.detail_width > 0u && l0 == 0u) colour *= detail_gain(m, k0, k1, fx, p, d);
  screen[i] = vec4(colour, 1.0);
  if (pc.depth == 0u) return;  // only depth compositing reads it (FramePipeline::enable_depth_output)

  uint r = min(uint(max(floor(near.v), 0.0)), uint(near.rows) - 1u);
  vec4 s = texelFetch(vpos, int(r * m.g.padded_columns + near.c));
  bool surface = s.w >= 0.0 || s.w <= kReconEmitterBase + 0.5;  // materials and emitters
  depth[i] = surface ? max(-rg_world_to_view(m, s.xyz, false).z, 0.0) : 0.0;
}
