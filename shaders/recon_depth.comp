#version 460
// Display-space linear depth, for depth compositing with the application's pixels: each
// pixel takes the grid cell its direction falls in (nearest sample, no filtering: depths
// must not blend across silhouettes) and stores that sample's view-space distance along -Z.
// 0 where the cell saw the sky or holds no sample (nothing at a finite distance). The
// displayed image does not depend on it.
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "fovea/shaders/recon_bindings.h"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/recon_grid.h"

layout(std430, binding = RECON_MAPS) readonly buffer Maps { ReconGrid maps[]; };
layout(std430, binding = RECON_TABLES) readonly buffer Tables { GridColumn tables[]; };
layout(std430, binding = RECON_DEPTH_POS) readonly buffer Pos { vec4 vpos[]; };  // world position, .w material code
layout(std430, binding = RECON_DEPTH_OUT) writeonly buffer Depth { float depth[]; };

#include "fovea/shaders/recon_map.h"

layout(push_constant) uniform Push { ReconResolvePush pc; };  // width, height

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= pc.width || p.y >= pc.height) return;
  ReconGrid m = maps[kReconCurrent];
  vec2 px = vec2(p) + 0.5;
  vec2 uv = rg_grid_coord(m, rg_pixel_to_dir(m, px), px);
  uint c = uint(clamp(int(floor(uv.x)), 0, int(m.g.columns) - 1));
  uint rows = max(rg_rows(m, c), 1u);
  uint r = min(uint(max(floor(rg_row_coord(m, c, uv.y)), 0.0)), rows - 1u);
  vec4 s = vpos[r * m.g.padded_columns + c];
  bool surface = s.w >= 0.0 || s.w <= kReconEmitterBase + 0.5;  // materials and emitters
  depth[p.y * pc.width + p.x] = surface ? max(-rg_world_to_view(m, s.xyz, false).z, 0.0) : 0.0;
}
