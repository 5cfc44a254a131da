// One sample of a sample grid (any distribution), as produced by the grid-generation
// shader and consumed by the path tracer and the reconstruction. Shared C++/GLSL.
#ifndef FOVEA_SHADERS_GRID_H
#define FOVEA_SHADERS_GRID_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

// flags: 0 means "trace this cell"; any bit set means the thread skips it.
FOVEA_CONST FOVEA_UINT kCellClipped = 1u;    // beyond the column's row count (VP clip)
FOVEA_CONST FOVEA_UINT kCellOffscreen = 2u;  // cell centre outside the view frustum
FOVEA_CONST FOVEA_UINT kCellHidden = 4u;     // cell centre inside the lens' hidden area
FOVEA_CONST FOVEA_UINT kCellKilled = 8u;     // randomly killed (linear fall-off)
FOVEA_CONST FOVEA_UINT kCellPadding = 16u;   // padding to whole 32x32 blocks
// A cell centre this close outside the display (pixels) is on it: a packed column's end rows
// are centred on the display's edge by construction, and float rounding must not decide.
FOVEA_CONST float kCellEdgeTolPx = 0.01f;

struct GridSample {
  float dir_x, dir_y, dir_z;  // unit view-space direction (OpenXR: -Z forward, +Y up)
  FOVEA_UINT flags;
  float screen_x, screen_y;   // continuous display pixel position, origin top-left, y down
  float ecc_deg;              // eccentricity from the gaze, degrees
  float footprint;            // sample spacing in display pixels (sqrt of pixels per sample)
};

#ifdef __cplusplus
static_assert(sizeof(GridSample) == 32);
}  // namespace fovea::shaders
#endif
#endif
