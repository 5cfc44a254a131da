// Per-frame description of a sample grid for the grid-generation shader (and any shader
// mapping between display and grid). Shared C++/GLSL; mirrors core::SampleDistribution.
#ifndef FOVEA_SHADERS_GRID_PARAMS_H
#define FOVEA_SHADERS_GRID_PARAMS_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

// GridParams.family
FOVEA_CONST FOVEA_UINT kFamilyAngularPolar = 0u;  // VP: radius = eccentricity (deg) around the gaze
FOVEA_CONST FOVEA_UINT kFamilyScreenPolar = 1u;   // paper VP, log-polar: radius in pixels
FOVEA_CONST FOVEA_UINT kFamilyCartesian = 2u;     // raster scaled to the display

// One column of a polar grid: radius range [r0, r1) (linear within the column), rows, and
// the arc of φ its rows cover: [phi0, phi0 + 2π − phi_gap) radians. phi_gap = 0 is a full
// ring (rows wrap in φ); > 0 a packed ring covering only its visible arc (rows do not wrap).
struct GridColumn {
  float r0, r1;
  FOVEA_UINT rows;
  float phi0;
  float phi_gap;
  float pad0, pad1, pad2;
};

struct GridParams {
  FOVEA_UINT family, columns, rows, padded_columns;
  FOVEA_UINT padded_rows, frame, seed, kill;      // kill: 1 = linear fall-off random killing
  float gaze_x, gaze_y, gaze_z, width;            // gaze: unit view-space direction
  float b1_x, b1_y, b1_z, height;                 // b1, b2: orthonormal basis around the gaze
  float b2_x, b2_y, b2_z, has_mask;               // has_mask: 1 = hidden-area bitmask bound
  float tan_left, tan_right, tan_up, tan_down;    // view frustum in tangent space
  float gaze_px_x, gaze_px_y, jitter_u, jitter_v; // gaze display position, cell jitter
  float fl_deg, pl_deg, pp, pad0;                 // linear fall-off p(e) (Weier 2016)
};

#ifdef __cplusplus
static_assert(sizeof(GridColumn) == 32);
static_assert(sizeof(GridParams) == 128);
}  // namespace fovea::shaders
#endif
#endif
