// GLSL mirror of core::SampleDistribution's mappings (core/src/*distribution*.cpp,
// visual_polar.cpp, screen_polar.cpp): grid cell -> view direction and display position.
// Needs: GridParams P (uniform) and GridColumn cols[] (storage) declared by the includer.
#ifndef FOVEA_SHADERS_GRID_MAP_GLSL
#define FOVEA_SHADERS_GRID_MAP_GLSL

const float kPi = 3.14159265358979323846;
const float kDegToRad = kPi / 180.0;

vec3 gm_gaze() { return vec3(P.gaze_x, P.gaze_y, P.gaze_z); }
vec3 gm_b1() { return vec3(P.b1_x, P.b1_y, P.b1_z); }
vec3 gm_b2() { return vec3(P.b2_x, P.b2_y, P.b2_z); }

vec3 gm_pixel_to_dir(vec2 px) {
  float tx = P.tan_left + (px.x / P.width) * (P.tan_right - P.tan_left);
  float ty = P.tan_up - (px.y / P.height) * (P.tan_up - P.tan_down);
  return normalize(vec3(tx, ty, -1.0));
}

// Display position of a direction; directions not in front of the eye land far outside.
vec2 gm_dir_to_pixel(vec3 d) {
  if (!(d.z < 0.0)) return vec2(-1e6);
  vec2 t = d.xy / -d.z;
  vec2 px = vec2((t.x - P.tan_left) / (P.tan_right - P.tan_left) * P.width,
                 (P.tan_up - t.y) / (P.tan_up - P.tan_down) * P.height);
  return clamp(px, vec2(-1e6), vec2(1e6));
}

// Angle between unit vectors in degrees, accurate near 0 (no acos of values near 1).
float gm_angle_deg(vec3 a, vec3 b) { return atan(length(cross(a, b)), dot(a, b)) / kDegToRad; }

float gm_pixels_per_deg2(vec3 d) {
  vec2 t = d.xy / -d.z;
  float q = 1.0 + dot(t, t);
  return (P.width / (P.tan_right - P.tan_left)) * (P.height / (P.tan_up - P.tan_down)) * q * sqrt(q) *
         kDegToRad * kDegToRad;
}

// Weier et al. 2016 / dissertation Eq. 4.1 keep probability.
float gm_keep_probability(float e) {
  if (e <= P.fl_deg) return 1.0;
  if (e >= P.pl_deg) return P.pp;
  return 1.0 + (e - P.fl_deg) * (P.pp - 1.0) / (P.pl_deg - P.fl_deg);
}

// Direction and display position of the grid position (col, row) + 0.5 + jit of a cell that
// exists (not padding); returns the cell's display pixels (its footprint's area).
float gm_map(uint col, uint row, vec2 jit, out vec3 dir, out vec2 px) {
  float u = float(col) + 0.5 + jit.x;
  float v = float(row) + 0.5 + jit.y;
  if (P.family == kFamilyCartesian) {
    px = vec2(u * P.width / float(P.columns), v * P.height / float(P.rows));
    dir = gm_pixel_to_dir(px);
    return P.width * P.height / (float(P.columns) * float(P.rows));
  }
  GridColumn c = cols[col];
  float f = clamp(u - float(col), 0.0, 1.0);
  float r = c.r0 + f * (c.r1 - c.r0);
  float arc = 2.0 * kPi - c.phi_gap;  // a full ring, or a packed column's visible arc
  float phi = 2.0 * kPi * v / float(c.rows);
  if (c.phi_gap > 0.0) {
    // In turns, reduced to [−½, ½): float sin/cos lose accuracy on arguments beyond 2π.
    float turns = c.phi0 / (2.0 * kPi) + (arc / (2.0 * kPi)) * v / float(c.rows);
    phi = 2.0 * kPi * (fract(turns + 0.5) - 0.5);
  }
  vec2 cs = vec2(cos(phi), sin(phi));
  if (P.family == kFamilyAngularPolar) {
    float e = r * kDegToRad;
    dir = normalize(cos(e) * gm_gaze() + sin(e) * (cs.x * gm_b1() + cs.y * gm_b2()));
    px = gm_dir_to_pixel(dir);
    // Ring solid angle 2π(cos r0 − cos r1) = 4π sin(mid) sin(half-width): no cancellation.
    float sr = 4.0 * kPi * sin(0.5 * (c.r0 + c.r1) * kDegToRad) * sin(0.5 * (c.r1 - c.r0) * kDegToRad);
    return sr * (arc / (2.0 * kPi)) / (kDegToRad * kDegToRad) / float(c.rows) * gm_pixels_per_deg2(dir);
  }
  px = vec2(P.gaze_px_x, P.gaze_px_y) + r * cs;
  dir = gm_pixel_to_dir(px);
  return 0.5 * arc * (c.r1 - c.r0) * (c.r1 + c.r0) / float(c.rows);
}

// The sample of cell (col, row) at offset `jit` from the cell centre; `centre_px` is the
// centre's display position. Whether a cell is on the display is its centre's, whatever the
// jitter: a cell at the display's or the lens' edge stays traced (or not) from frame to
// frame, and so keeps its history (a cell that came and went with the jitter restarted every
// time it came back, and its single samples showed as blobs).
GridSample gm_sample(uint col, uint row, vec2 jit, out vec2 centre_px) {
  GridSample s;
  s.flags = 0u;
  centre_px = vec2(-1e6);
  if (col >= P.columns || row >= P.rows) {
    s.dir_x = 0.0; s.dir_y = 0.0; s.dir_z = -1.0;
    s.flags = kCellPadding;
    s.screen_x = 0.0; s.screen_y = 0.0; s.ecc_deg = 0.0; s.footprint = 0.0;
    return s;
  }
  vec3 dir;
  vec2 px;
  float pixels_per_cell = gm_map(col, row, jit, dir, px);
  if (P.family != kFamilyCartesian && row >= cols[col].rows) s.flags |= kCellClipped;
  centre_px = px;
  if (jit != vec2(0.0)) {
    vec3 centre_dir;
    gm_map(col, row, vec2(0.0), centre_dir, centre_px);
  }
  float ecc = gm_angle_deg(dir, gm_gaze());
  if (P.kill != 0u) {
    float x = hash_to_unit(hash3(col, row, P.frame * 0x9E3779B9u + P.seed));
    if (!(x < gm_keep_probability(ecc))) s.flags |= kCellKilled;
  }
  if (!(all(greaterThanEqual(centre_px, vec2(-kCellEdgeTolPx))) &&
        all(lessThanEqual(centre_px, vec2(P.width, P.height) + kCellEdgeTolPx))))
    s.flags |= kCellOffscreen;
  s.dir_x = dir.x; s.dir_y = dir.y; s.dir_z = dir.z;
  s.screen_x = px.x;
  s.screen_y = px.y;
  s.ecc_deg = ecc;
  s.footprint = clamp(sqrt(max(pixels_per_cell, 0.0)), 1e-6, 1e6);
  return s;
}

#endif
