// GLSL only: grid-space mapping helpers of the reconstruction (see recon_grid.h). Include
// after declaring the mapping buffer and the column table's texel buffer:
//   buffer ... { ReconGrid maps[]; }  and  uniform textureBuffer tables;
// and, in kernels that define RG_RADIUS_LUT, the mappings' radius lookup tables:
//   uniform utextureBuffer radius_luts;
#ifndef FOVEA_SHADERS_RECON_MAP_H
#define FOVEA_SHADERS_RECON_MAP_H
const float kRgPi = 3.14159265358979323846;

// Column k of the bound column tables: two RGBA32F texels per GridColumn (read per
// invocation at a per-invocation column, which lavapipe fetches as one vector gather per
// texel; docs/gpu.md, "Texel buffers").
GridColumn rg_table(uint k) {
  const vec4 a = texelFetch(tables, int(2u * k)), b = texelFetch(tables, int(2u * k + 1u));
  return GridColumn(a.x, a.y, floatBitsToUint(a.z), a.w, b.x, b.y, b.z, b.w);
}

vec3 rg_gaze(ReconGrid m) { return vec3(m.g.gaze_x, m.g.gaze_y, m.g.gaze_z); }

vec3 rg_world_to_view(ReconGrid m, vec3 p, bool is_direction) {
  vec3 d = is_direction ? p : p - vec3(m.eye_x, m.eye_y, m.eye_z);
  return vec3(dot(vec3(m.w2v0_x, m.w2v0_y, m.w2v0_z), d), dot(vec3(m.w2v1_x, m.w2v1_y, m.w2v1_z), d),
              dot(vec3(m.w2v2_x, m.w2v2_y, m.w2v2_z), d));
}

vec3 rg_view_to_world_dir(ReconGrid m, vec3 d) {
  return vec3(m.w2v0_x, m.w2v0_y, m.w2v0_z) * d.x + vec3(m.w2v1_x, m.w2v1_y, m.w2v1_z) * d.y +
         vec3(m.w2v2_x, m.w2v2_y, m.w2v2_z) * d.z;
}

// Tangent-space position (x right, y up) of display pixel position px.
vec2 rg_pixel_tan(ReconGrid m, vec2 px) {
  return vec2(m.g.tan_left + (px.x / m.g.width) * (m.g.tan_right - m.g.tan_left),
              m.g.tan_up - (px.y / m.g.height) * (m.g.tan_up - m.g.tan_down));
}

vec3 rg_pixel_to_dir(ReconGrid m, vec2 px) { return normalize(vec3(rg_pixel_tan(m, px), -1.0)); }

// Angle (radians) one pixel step spans at tangent position t, along x (vertical = false)
// or y: |∂d/∂t_x| = √(1 + t_y²) / (1 + |t|²) for d = normalize(t, -1), times the step in
// tangent units (the exact finite difference differs by O(step²)).
float rg_pixel_angle(ReconGrid m, vec2 t, bool vertical) {
  float step_t = vertical ? (m.g.tan_up - m.g.tan_down) / m.g.height : (m.g.tan_right - m.g.tan_left) / m.g.width;
  float across = vertical ? t.x : t.y;
  return step_t * sqrt(1.0 + across * across) / (1.0 + dot(t, t));
}

// View direction -> display pixel; false when not in front of the eye or off the raster.
bool rg_dir_to_pixel(ReconGrid m, vec3 d, out vec2 px) {
  px = vec2(-1.0);
  if (!(d.z < 0.0)) return false;
  vec2 t = d.xy / -d.z;
  px = vec2((t.x - m.g.tan_left) / (m.g.tan_right - m.g.tan_left) * m.g.width,
            (m.g.tan_up - t.y) / (m.g.tan_up - m.g.tan_down) * m.g.height);
  return px.x >= 0.0 && px.y >= 0.0 && px.x <= m.g.width && px.y <= m.g.height;
}

// Rows of column c (the raster's row count for the Cartesian family).
uint rg_rows(ReconGrid m, uint c) { return m.g.family == kFamilyCartesian ? m.g.rows : rg_table(m.table_offset + c).rows; }

// Column search range [x, y) for radius r: the whole table, or — in kernels that define
// RG_RADIUS_LUT and bind radius_luts, for a mapping that has a lookup table — the few
// columns the radius's bin allows, so the search below takes ~1 step instead of
// log2(columns). Bin k of the table holds the last column whose r0 is <= (k - 0.5) / scale,
// so a radius in bin k = floor(r·scale) lies in a column of [lut[k], lut[k + 2]]: the
// half-bin margins absorb the rounding of r·scale, and the narrowed search finds exactly
// the column the full search finds (reconstruct::radius_lut).
#ifdef RG_RADIUS_LUT
uvec2 rg_column_range(ReconGrid m, float r) {
  if (!(m.lut_scale > 0.0)) return uvec2(0u, m.g.columns);
  const float last = float(kReconRadiusLutSize - 1u);
  uint k = m.lut_offset + min(uint(clamp(r * m.lut_scale, 0.0, last)), kReconRadiusLutSize - 1u);
  return uvec2(texelFetch(radius_luts, int(k)).x, texelFetch(radius_luts, int(k + 2u)).x + 1u);
}
#else
uvec2 rg_column_range(ReconGrid m, float r) { return uvec2(0u, m.g.columns); }
#endif

// Column c's table entry; for the Cartesian raster a full "ring" of the raster's rows (no
// gap), so the helpers below that take an entry serve every family. Kernels that need
// several of a column's properties load its entry a single time.
GridColumn rg_column(ReconGrid m, uint c) {
  if (m.g.family == kFamilyCartesian) return GridColumn(float(c), float(c + 1u), m.g.rows, 0.0, 0.0, 0.0, 0.0, 0.0);
  return rg_table(m.table_offset + c);
}

// Whether a column's rows wrap in φ: a full polar ring; not a column packed to its visible
// arc (GridColumn::phi_gap > 0), nor the Cartesian raster.
bool rg_column_wraps(ReconGrid m, GridColumn col) { return m.g.family != kFamilyCartesian && col.phi_gap == 0.0; }
bool rg_wraps(ReconGrid m, uint c) { return rg_column_wraps(m, rg_column(m, c)); }

// Continuous row coordinate in a column (cell centres at +0.5) of grid coordinate t (φ / 2π
// on polar grids): φ from the start of the column's arc; a point in a packed column's gap
// (off the view) snaps to the nearer end of its arc (core PolarDistribution::screen_to_grid).
float rg_row_coord_of(GridColumn col, float t) {
  float rows = float(col.rows);
  if (col.phi_gap == 0.0) return t * rows;
  float span = 1.0 - col.phi_gap / (2.0 * kRgPi);
  float x = fract(t - col.phi0 / (2.0 * kRgPi));
  if (x > span) x = x - span < 1.0 - x ? span : 0.0;
  return x / span * rows;
}

// Grid coordinate t of row coordinate v of column c (the inverse of rg_row_coord_of).
float rg_row_to_t_of(GridColumn col, float v) {
  return fract(col.phi0 / (2.0 * kRgPi) + v / float(max(col.rows, 1u)) * (1.0 - col.phi_gap / (2.0 * kRgPi)));
}
float rg_row_to_t(ReconGrid m, uint c, float v) {
  if (m.g.family == kFamilyCartesian) return v / float(max(m.g.rows, 1u));
  return rg_row_to_t_of(rg_table(m.table_offset + c), v);
}

// r modulo rows (in [0, rows)) for rows > 0 and |r| < 2^22, without an integer division:
// lavapipe has no vector integer division and runs one per SIMD lane, where the float
// quotient is one vector instruction; the guards undo its rounding at exact multiples.
int rg_wrap(int r, int rows) {
  r -= rows * int(floor(float(r) / float(rows)));
  return r < 0 ? r + rows : (r >= rows ? r - rows : r);
}

// Row r of a column of `rows` rows, r within one turn of the column (-rows <= r < 2 rows):
// wrapped on a full ring, clamped to the column's ends otherwise.
int rg_row_index(int r, int rows, bool wraps) {
  if (!wraps) return clamp(r, 0, rows - 1);
  return r < 0 ? r + rows : (r >= rows ? r - rows : r);
}

// The two rows of a column of `rows` rows around row coordinate v (cell centres at +0.5)
// and the weight f of r1: a full ring wraps (v in [0, rows]: one conditional add/subtract,
// no integer division), a packed column or the raster clamps.
void rg_row_pair(int rows, bool wraps, float v, out int r0, out int r1, out float f) {
  float vr = v - 0.5;
  float r0f = floor(vr);
  f = vr - r0f;
  r0 = rg_row_index(int(r0f), rows, wraps);
  r1 = rg_row_index(int(r0f) + 1, rows, wraps);
}

// The last column i in [range.x, range.y) with r0(i) <= r (range.x when none; the columns'
// r0 are increasing), by binary search.
uint rg_column_of(ReconGrid m, float r, uvec2 range) {
  uint lo = range.x, hi = range.y;
  while (hi - lo > 1u) {
    uint mid = (lo + hi) >> 1;
    if (rg_table(m.table_offset + mid).r0 <= r) lo = mid; else hi = mid;
  }
  return lo;
}

// Continuous column coordinate of radius r (core PolarDistribution::screen_to_grid): the
// last boundary <= r, linear inside the column, clamped to the table (ρ clamp).
float rg_radius_to_u(ReconGrid m, float r) {
  uint i = rg_column_of(m, r, rg_column_range(m, r));
  GridColumn c = rg_table(m.table_offset + i);
  float w = c.r1 - c.r0;
  return float(i) + (w > 0.0 ? clamp((r - c.r0) / w, 0.0, 1.0) : 0.5);
}

// Polar coordinates around the gaze of view direction d at display pixel px: (radius, φ),
// the radius in the family's units (eccentricity in degrees for angular polar, pixels for
// screen polar), φ in [-π, π] from the basis b1 (angular) or the display's x axis (screen).
vec2 rg_polar(ReconGrid m, vec3 d, vec2 px) {
  if (m.g.family == kFamilyAngularPolar) {
    vec3 g = rg_gaze(m);
    return vec2(atan(length(cross(d, g)), dot(d, g)) * (180.0 / kRgPi),
                atan(dot(d, vec3(m.g.b2_x, m.g.b2_y, m.g.b2_z)), dot(d, vec3(m.g.b1_x, m.g.b1_y, m.g.b1_z))));
  }
  vec2 q = px - vec2(m.g.gaze_px_x, m.g.gaze_px_y);
  return vec2(length(q), atan(q.y, q.x));
}

// Grid coordinate (u = column coordinate, cell centres at +0.5; t = φ / 2π in [0, 1) for
// polar grids, y / height for the Cartesian raster) of view direction d at display pixel px.
vec2 rg_grid_coord(ReconGrid m, vec3 d, vec2 px) {
  if (m.g.family == kFamilyCartesian) return vec2(px.x * float(m.g.columns) / m.g.width, px.y / m.g.height);
  vec2 rp = rg_polar(m, d, px);
  float t = rp.y / (2.0 * kRgPi);
  t -= floor(t);
  return vec2(rg_radius_to_u(m, rp.x), t);
}

// World point (or, is_direction, world direction of a sky sample) -> grid coordinate of
// mapping m; false when it is behind the eye, or off the display unless `off_display`: then
// such a point maps beyond the grid's edge, where the taps clamp (a cell is traced when its
// centre is on the display, and its jittered sample may leave it: grid_map.glsl).
bool rg_world_to_grid(ReconGrid m, vec3 p, bool is_direction, bool off_display, out vec2 uv) {
  uv = vec2(0.0);
  vec3 d = rg_world_to_view(m, p, is_direction);
  vec2 px;
  if (!rg_dir_to_pixel(m, d, px) && !(off_display && d.z < 0.0)) return false;
  uv = rg_grid_coord(m, normalize(d), clamp(px, vec2(-1e6), vec2(1e6)));
  return true;
}

// Linear size of a cell of column c: the square root of its area in the family's radius
// units (degrees of visual angle for angular polar, pixels for screen polar); 1 for the
// Cartesian raster, whose cells never change size. From the column's entry (rg_column).
float rg_column_cell_size(ReconGrid m, GridColumn col) {
  if (m.g.family == kFamilyCartesian) return 1.0;
  float rm = 0.5 * (col.r0 + col.r1);
  float circumference = m.g.family == kFamilyAngularPolar ? 360.0 * sin(rm * (kRgPi / 180.0)) : 2.0 * kRgPi * rm;
  float turns = 1.0 - col.phi_gap / (2.0 * kRgPi);
  return sqrt(max((col.r1 - col.r0) * circumference * turns / float(max(col.rows, 1u)), 0.0));
}

// The four bilinear taps of (u, t): two columns (ρ clamped; `cols`, taps 0–1 in cols.x and
// 2–3 in cols.y), and in each column the two rows around its row coordinate of t (φ wraps on
// full rings, clamps on packed columns and the raster); each column's table entry read
// once, and the linear size of each column's cells from it (rg_column_cell_size). Cell indices
// row * padded_columns + column; weights sum to 1.
void rg_taps(ReconGrid m, vec2 uv, out uvec4 idx, out vec4 w, out uvec2 cols, out vec2 sizes) {
  float uc = uv.x - 0.5;
  float c0f = floor(uc);
  float fx = uc - c0f;
  for (int i = 0; i < 2; ++i) {
    uint c = uint(clamp(int(c0f) + i, 0, int(m.g.columns) - 1));
    cols[i] = c;
    GridColumn col = rg_column(m, c);
    uint rows = max(col.rows, 1u);
    float vr = rg_row_coord_of(col, uv.y) - 0.5;
    float r0f = floor(vr);
    float fy = vr - r0f;
    int r0 = int(r0f), r1 = r0 + 1;
    if (rg_column_wraps(m, col)) {
      r0 = rg_wrap(r0, int(rows));
      r1 = rg_wrap(r1, int(rows));
    } else {
      r0 = clamp(r0, 0, int(rows) - 1);
      r1 = clamp(r1, 0, int(rows) - 1);
    }
    float wc = i == 0 ? 1.0 - fx : fx;
    idx[2 * i] = uint(r0) * m.g.padded_columns + c;
    idx[2 * i + 1] = uint(r1) * m.g.padded_columns + c;
    w[2 * i] = wc * (1.0 - fy);
    w[2 * i + 1] = wc * fy;
    sizes[i] = rg_column_cell_size(m, col);
  }
}

// Catmull–Rom weights (Mitchell–Netravali B = 0, C = ½) of the taps at −1, 0, 1, 2 around
// f in [0, 1) past tap 0: they sum to 1 and give tap 0 alone at f = 0.
vec4 rg_catmull_rom(float f) {
  float f2 = f * f, f3 = f2 * f;
  return vec4(-0.5 * f3 + f2 - 0.5 * f, 1.5 * f3 - 2.5 * f2 + 1.0, -1.5 * f3 + 2.0 * f2 + 0.5 * f, 0.5 * f3 - 0.5 * f2);
}

// A cell of mapping m as its neighbourhood needs it: its column and the grid coordinate t
// of its centre (computed once for the 3×3 neighbours: the index division and the φ of the
// row were most of a neighbourhood's cost on lavapipe).
struct RgCell {
  uint col;
  float t;
};

RgCell rg_cell(ReconGrid m, uint j) {
  uint pcols = m.g.padded_columns, col = j % pcols;
  return RgCell(col, rg_row_to_t(m, col, float(j / pcols) + 0.5));
}

// A column next to a cell, as its neighbourhood reads it: the column, its rows, whether
// they wrap, and its row at the cell's φ. Taken once per column (rg_column_next_to), its
// neighbours of the cell follow from it with integer arithmetic (rg_row_next_to): each
// column's table entry and row coordinate are computed once, not once per neighbour.
struct RgColumnNear {
  uint col;
  int rows;
  bool wraps;
  int row;
};

// The column dc over from cell c of mapping m; false beyond the grid.
bool rg_column_next_to(ReconGrid m, RgCell c, int dc, out RgColumnNear n) {
  n = RgColumnNear(0u, 1, false, 0);
  int cc = int(c.col) + dc;
  if (cc < 0 || cc >= int(m.g.columns)) return false;
  GridColumn col = rg_column(m, uint(cc));
  n = RgColumnNear(uint(cc), int(max(col.rows, 1u)), rg_column_wraps(m, col), int(floor(rg_row_coord_of(col, c.t))));
  return true;
}

// Cell k, dr rows from n's row in n's column (φ wraps on full rings; false beyond the raster
// or the ends of a column packed to its visible arc).
bool rg_row_next_to(ReconGrid m, RgColumnNear n, int dr, out uint k) {
  k = 0u;
  int rr = n.row + dr;
  if (rr < 0 || rr >= n.rows) {
    if (!n.wraps) return false;
    rr = rg_wrap(rr, n.rows);
  }
  k = uint(rr) * m.g.padded_columns + n.col;
  return true;
}

// Where the centre of the current frame's cell `col` lies in mapping m, given the grid
// coordinate uv in m of the cell's (jittered) sample: the current jitter (cells of `cur`) is
// taken off, so taps read cells whose accumulated content stands for their centres (TAA's
// unjittered reprojection). Exact when m shares cur's gaze (a still gaze, the other eye);
// under gaze motion the offset (≤ half a cell) is applied in m's cells.
// `col` is the cell's column entry in cur (rg_column).
vec2 rg_unjitter(ReconGrid cur, GridColumn col, ReconGrid m, vec2 uv) {
  float t = uv.y - cur.g.jitter_v * (1.0 - col.phi_gap / (2.0 * kRgPi)) / float(max(col.rows, 1u));
  return vec2(uv.x - cur.g.jitter_u, m.g.family != kFamilyCartesian ? fract(t) : t);
}

// Weight of taps from cells of linear size `size`, at `ratio` = size / the sample's own cell
// size: 1 up to `keep`, falling linearly to 0 at `reject` (ReconSettings). A coarser cell
// holds a blurred estimate (after a saccade the new fovea lands on old periphery); reusing it
// would keep the fovea blurred for many frames.
float rg_coarse_weight(float size, float own_size, float keep, float reject) {
  float ratio = size / max(own_size, 1e-12);
  return clamp((reject - ratio) / max(reject - keep, 1e-6), 0.0, 1.0);
}

// Tap validity (see kRecon* above). vpos: xyz world position (sky: world direction),
// w material (-1 sky, kReconNoSample none); n: unit normal; depth: the sample's distance.
bool rg_tap_valid(vec4 vpos, vec3 n, float depth, vec4 tap_pos, vec3 tap_n) {
  if (rg_no_sample(vpos.w) || tap_pos.w != vpos.w) return false;
  if (vpos.w == kReconSky) return dot(vpos.xyz, tap_pos.xyz) > 0.9995;  // nearly the same direction
  vec3 dn = n - tap_n;
  if (dot(dn, dn) >= kReconNormalLimit2) return false;
  vec3 dp = tap_pos.xyz - vpos.xyz;
  float tol = max(depth, 1e-3);
  return abs(dot(dp, n)) < kReconPlaneTol * tol && length(dp) < kReconDistTol * tol;
}
#endif
