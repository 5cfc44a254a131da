#version 460
// Resolve to the display (P5 §3.4): every display pixel computes its grid coordinate through
// the current mapping (the column found through the per-frame radius lookup table,
// recon_radius_lut.comp) and samples the grid — trilinear over the φ-only mip chain
// (bilinear in ρ between the two columns, each with its own row count; φ wraps, ρ clamps).
// The level comes from the pixel's footprint along φ in rows of its column (analytic). The
// same grid coordinate gives the display-space depth: the nearest cell's sample's view-space
// distance along -Z (no filtering: depths must not blend across silhouettes), 0 where that
// cell saw the sky or holds no sample; for depth compositing, the image does not use it.
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
layout(std430, binding = RECON_RESOLVE_POS) readonly buffer Pos { vec4 vpos[]; };  // world position, .w material code
layout(std430, binding = RECON_RESOLVE_DEPTH) writeonly buffer Depth { float depth[]; };
layout(std430, binding = RECON_RESOLVE_LUT) readonly buffer Lut {
  ReconRadiusLutHeader lut_header;
  uint lut[];
};

#define RG_RADIUS_LUT
#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconResolvePush pc; };

// Bilinear at level `level` of the column pair around u; rows wrap (full polar rings, r0 in
// [-1, rows) and r1 in [0, rows]: one conditional add/subtract, no integer division) or clamp
// (the raster, and columns packed to their visible arc).
vec4 fetch_level(ReconGrid m, vec2 uv, uint level) {
  float uc = uv.x - 0.5;
  float c0f = floor(uc);
  float fx = uc - c0f;
  float scale = float(1u << level);
  uint base = level_offset[level];
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
      r0 += r0 < 0 ? rows : 0;
      r1 -= r1 >= rows ? rows : 0;
    } else {
      r0 = clamp(r0, 0, rows - 1);
      r1 = clamp(r1, 0, rows - 1);
    }
    float wc = i == 0 ? 1.0 - fx : fx;
    acc += wc * ((1.0 - fy) * mips[base + uint(r0) * m.g.padded_columns + c] +
                 fy * mips[base + uint(r1) * m.g.padded_columns + c]);
  }
  return acc;
}

// Footprint of the pixel along φ in rows of column c (the LOD's argument): a pixel of angular
// size δ (the larger of its two sides) at eccentricity e spans δ / (2π sin e) of the circle
// (angular polar); at radius r one pixel spans 1 / (2π r) (screen polar).
float phi_footprint(ReconGrid m, vec2 t, vec3 d, vec2 px, vec2 uv) {
  uint c = uint(clamp(int(uv.x), 0, int(m.g.columns) - 1));
  float rows = rg_turn_rows(m, c);
  if (m.g.family == kFamilyAngularPolar) {
    float delta = max(rg_pixel_angle(m, t, false), rg_pixel_angle(m, t, true));
    return delta * rows / (2.0 * kRgPi * max(length(cross(d, rg_gaze(m))), 1e-6));
  }
  float r = length(px - vec2(m.g.gaze_px_x, m.g.gaze_px_y));
  return rows / (2.0 * kRgPi * max(r, 1e-6));
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
  float lod = 0.0;
  if (pc.levels > 1u && polar) lod = clamp(log2(max(phi_footprint(m, t, d, px, uv), 1.0)), 0.0, float(pc.levels - 1u));
  uint i = p.y * pc.width + p.x;
  if (pc.grid_coords != 0u) {
    screen[i] = vec4(uv, lod, 0.0);
    return;
  }
  uint l0 = uint(floor(lod));
  float f = lod - float(l0);
  vec4 v = fetch_level(m, uv, l0);
  if (f > 0.0 && l0 + 1u < pc.levels) v = mix(v, fetch_level(m, uv, l0 + 1u), f);
  screen[i] = v.w > 1e-6 ? vec4(v.rgb / v.w, 1.0) : vec4(0.0, 0.0, 0.0, 1.0);

  uint c = uint(clamp(int(floor(uv.x)), 0, int(m.g.columns) - 1));
  uint rows = max(rg_rows(m, c), 1u);
  uint r = min(uint(max(floor(rg_row_coord(m, c, uv.y)), 0.0)), rows - 1u);
  vec4 s = vpos[r * m.g.padded_columns + c];
  bool surface = s.w >= 0.0 || s.w <= kReconEmitterBase + 0.5;  // materials and emitters
  depth[i] = surface ? max(-rg_world_to_view(m, s.xyz, false).z, 0.0) : 0.0;
}
