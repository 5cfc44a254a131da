#version 460
// Resolve to the display (P5 §3.4): every display pixel computes its grid coordinate through
// the current mapping and samples the grid — trilinear over the φ-only mip chain (bilinear
// in ρ between the two columns, each with its own row count; φ wraps, ρ clamps). The level
// comes from the pixel's footprint along φ measured in rows of its column (analytic: one grid
// coordinate per pixel instead of three finite-difference ones).
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(std430, binding = RECON_TABLES) readonly buffer Tables { GridColumn tables[]; };
layout(std430, binding = RECON_RESOLVE_MIPS) readonly buffer Mips { vec4 mips[]; };
layout(std430, binding = RECON_RESOLVE_OFFSETS) readonly buffer Offsets { uint level_offset[]; };
layout(std430, binding = RECON_RESOLVE_SCREEN) writeonly buffer Screen { vec4 screen[]; };

#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconResolvePush pc; };

vec2 coord(ReconGrid m, vec2 px) { return rg_grid_coord(m, rg_pixel_to_dir(m, px), px); }

vec4 fetch_level(ReconGrid m, vec2 uv, uint level) {
  float uc = uv.x - 0.5;
  float c0f = floor(uc);
  float fx = uc - c0f;
  float scale = float(1u << level);
  vec4 acc = vec4(0.0);
  for (int i = 0; i < 2; ++i) {
    uint c = uint(clamp(int(c0f) + i, 0, int(m.g.columns) - 1));
    uint full = max(rg_rows(m, c), 1u);
    int rows = int((full + (1u << level) - 1u) >> level);
    float vr = rg_row_coord(m, c, uv.y) / scale - 0.5;
    float r0f = floor(vr);
    float fy = vr - r0f;
    int r0 = int(r0f), r1 = r0 + 1;
    if (rg_wraps(m, c)) {
      r0 = (r0 % rows + rows) % rows;
      r1 = r1 % rows;
    } else {
      r0 = clamp(r0, 0, rows - 1);
      r1 = clamp(r1, 0, rows - 1);
    }
    float wc = i == 0 ? 1.0 - fx : fx;
    uint base = level_offset[level];
    acc += wc * ((1.0 - fy) * mips[base + uint(r0) * m.g.padded_columns + c] +
                 fy * mips[base + uint(r1) * m.g.padded_columns + c]);
  }
  return acc;
}

// Footprint of the pixel along φ in rows of column c (the LOD's argument), analytically:
// a pixel of angular size δ at eccentricity r spans δ / (360° sin r) of the circle (angular
// polar), one pixel at radius r spans 1 / (2π r) (screen polar).
float phi_footprint(ReconGrid m, vec2 px, vec2 uv) {
  uint c = uint(clamp(int(uv.x), 0, int(m.g.columns) - 1));
  float rows = rg_turn_rows(m, c);
  if (m.g.family == kFamilyAngularPolar) {
    vec3 d = rg_pixel_to_dir(m, px), g = rg_gaze(m);
    vec3 dx = rg_pixel_to_dir(m, px + vec2(1.0, 0.0)), dy = rg_pixel_to_dir(m, px + vec2(0.0, 1.0));
    float delta = max(atan(length(cross(d, dx)), dot(d, dx)), atan(length(cross(d, dy)), dot(d, dy)));
    return delta * rows / (2.0 * kRgPi * max(length(cross(d, g)), 1e-6));
  }
  float r = length(px - vec2(m.g.gaze_px_x, m.g.gaze_px_y));
  return rows / (2.0 * kRgPi * max(r, 1e-6));
}

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  ReconGrid m = maps[kReconCurrent];
  vec2 px = vec2(p) + 0.5;
  vec2 uv = coord(m, px);
  float lod = 0.0;
  if (pc.levels > 1u && m.g.family != kFamilyCartesian)
    lod = clamp(log2(max(phi_footprint(m, px, uv), 1.0)), 0.0, float(pc.levels - 1u));
  uint l0 = uint(floor(lod));
  float f = lod - float(l0);
  vec4 v = fetch_level(m, uv, l0);
  if (f > 0.0 && l0 + 1u < pc.levels) v = mix(v, fetch_level(m, uv, l0 + 1u), f);
  screen[p.y * pc.width + p.x] = v.w > 1e-6 ? vec4(v.rgb / v.w, 1.0) : vec4(0.0, 0.0, 0.0, 1.0);
}
