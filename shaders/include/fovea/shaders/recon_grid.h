// Reconstruction in grid space (recon_*.comp), shared C++/GLSL: one grid mapping with its
// eye pose (the current frame's, the previous frame's, the other eye's), push constants,
// and — in GLSL — world/display position -> continuous grid coordinate and the bilinear
// taps of a jagged polar grid (rows differ per column, φ wraps, ρ clamps).
#ifndef FOVEA_SHADERS_RECON_GRID_H
#define FOVEA_SHADERS_RECON_GRID_H
#include "fovea/shaders/common.h"
#include "fovea/shaders/grid_params.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

// A grid mapping (core::SampleDistribution::gpu_params) plus the eye's world-to-view
// transform (rows of the rotation, then the eye position), where its column table starts
// in the bound table buffer, and where its radius -> column lookup table starts in the bound
// table of those (lut_scale > 0; 0: none, the column search takes the whole table).
struct ReconGrid {
  GridParams g;
  float w2v0_x, w2v0_y, w2v0_z, eye_x;
  float w2v1_x, w2v1_y, w2v1_z, eye_y;
  float w2v2_x, w2v2_y, w2v2_z, eye_z;
  FOVEA_UINT table_offset, valid;  // valid = 0: no such mapping (first frame)
  FOVEA_UINT lut_offset;           // first entry of its radius lookup table
  float lut_scale;                 // that table's bins per radius unit
};

// Slots of the per-eye mapping buffer.
FOVEA_CONST FOVEA_UINT kReconCurrent = 0u;
FOVEA_CONST FOVEA_UINT kReconPrevious = 1u;
FOVEA_CONST FOVEA_UINT kReconOther = 2u;

// Validity of a history/other-eye tap (BMFR §3.2, Gersthofer §3.4.1): same material, normals
// within |Δn|² < 0.25 (BMFR's Sponza limit, ≈ 29°), and the tap's position within
// kReconPlaneTol·depth of the sample's tangent plane (scale-free, so large peripheral
// cells on a plane pass while a foreground/background pair does not).
FOVEA_CONST float kReconNormalLimit2 = 0.25f;
FOVEA_CONST float kReconPlaneTol = 0.03f;
FOVEA_CONST float kReconDistTol = 0.25f;  // and |Δp| < this·depth (other surfaces far along the plane)

// Material codes in the validation data (.w of the position): >= 0 a surface, -1 the sky
// (position = direction), -2 no sample, <= -3 an emitter (−3 − material): emission is not
// a function of the regression's features, so emitters pass through BMFR unfitted.
FOVEA_CONST float kReconSky = -1.0f;
FOVEA_CONST float kReconNoSample = -2.0f;
FOVEA_CONST float kReconEmitterBase = -3.0f;

// Frames a cell counts as restarted after Phase I rejected its history for coarse cells (a
// saccade's new fovea): Phase I writes 1 at the restart, +1 per frame after, 0 beyond this
// or without a restart; TAA treats the window (recon_taa.comp).
FOVEA_CONST float kReconRestartFrames = 8.0f;

struct ReconAccumulatePush {
  FOVEA_UINT cells, has_history, indirect_fresh;  // indirect_fresh = 0: reuse history only
  FOVEA_UINT listed;  // 1: the cells of the live and reset tiles (live_cells.h), an indirect dispatch
  float alpha_min;                                     // EMA floor (BMFR Phase I: 0.2)
  float coarse_keep, coarse_reject;                    // cell-size test (ReconSettings, rg_coarse_weight)
  float landing_deg;      // as ReconPostPush: > 0 on a landing frame, the new fovea's angle
  float landing_history;  // samples the new fovea's history counts for there at most (ReconSettings)
  float held_deg;         // the view's motion since the last frame over kHeldCellShare (degrees)
  FOVEA_UINT unmoved;     // 1: the previous mapping is this one but for the jitter (GridMapping::unmoved)
  float pad2;
};

struct ReconSharePush {
  FOVEA_UINT cells, enabled;
  float coarse_keep, coarse_reject;  // as ReconAccumulatePush
  FOVEA_UINT edges;  // 1: flag the cells on a surface edge (BMFR's fit reads them)
  FOVEA_UINT listed, pad1, pad2;  // listed: as ReconAccumulatePush
};

struct ReconBmfrPush {
  FOVEA_UINT padded_columns, padded_rows, blocks_x, frame;
  FOVEA_INT offset_x, offset_y;  // this frame's block-grid displacement (cells, in [0, 32))
  float noise;                   // stochastic regularisation ε
  FOVEA_UINT columns;            // > 0: polar grid, blocks wrap in φ over the rows of columns[0, columns)
};

struct ReconPostPush {
  FOVEA_UINT cells, has_history, denoise;  // denoise = 0: remodulated accumulation only
  FOVEA_UINT listed;  // as ReconAccumulatePush
  float alpha_min, taa_alpha;  // BMFR Phase III: 0.1, TAA: 0.2
  float still;                // 0..1: how still the view is (1 − the EMA floors' share); recon_taa.comp
  float landing_deg;          // > 0: a landing frame; TAA takes no history within this angle of the gaze
};

struct ReconMipPush {
  FOVEA_UINT padded_columns, rows_in, rows_out, level_in;  // rows_*: allocated rows of the levels
  FOVEA_UINT offset_in, offset_out, pad0, pad1;            // element offsets in the mip buffer
};

// Textures at the display's resolution near the gaze (recon_resolve.comp, detail_gain): at most
// this factor between a pixel's own base colour and its cells' re-modulation albedo.
FOVEA_CONST float kReconDetailMaxGain = 4.0f;

struct ReconResolvePush {
  FOVEA_UINT width, height, levels, grid_coords;  // grid_coords = 1: write (u, t, LOD, 0) per pixel, for tests
  FOVEA_UINT lod_columns, depth, pad0, pad1;      // pixels of columns >= lod_columns have LOD 0 (Resolve, mip_reach);
                                                  // depth = 1: also write the display depth
  // The window of display pixels whose first hits RECON_RESOLVE_PRIMARY holds (width 0:
  // none), and the cosines of the angles from the gaze within which they re-modulate fully
  // and beyond which not at all.
  FOVEA_UINT detail_x0, detail_y0, detail_width, detail_height;
  float detail_cos_full, detail_cos_none;
  FOVEA_UINT lattice;  // lattice = 1: the lattice's reconstruction (below)
  // The Cartesian raster's Gaussian (ReconSettings::raster_gaussian): each side neighbour's
  // weight per axis; 0: each pixel its own cell (box).
  float raster_side;
};

// The lattice's reconstruction (ReconSettings::lattice_blur, recon_resolve.comp): where a polar
// cell spans more display pixels than kReconLatticeFromPx in a direction (across the rings or
// along them), the resample blends its tent between two cells into the cubic B-spline over
// four, fully from kReconLatticeFullPx. The tent's kinks at the cell centres draw the lattice
// there, rings about the gaze and spokes (docs/reconstruction.md, "The lattice's rings").
FOVEA_CONST float kReconLatticeFromPx = 1.5f;
FOVEA_CONST float kReconLatticeFullPx = 2.5f;

// Radius -> column lookup table of a polar mapping (reconstruct::radius_lut builds one per
// mapping and frame; recon_map.h, rg_column_range, reads it): kReconRadiusLutSize uniform
// radius bins over the column table's range, each holding the column search's lower bound,
// then 2 entries more (kReconRadiusLutEntries per mapping).
FOVEA_CONST FOVEA_UINT kReconRadiusLutSize = 4096u;
FOVEA_CONST FOVEA_UINT kReconRadiusLutEntries = kReconRadiusLutSize + 2u;

struct ReconBlurPush {
  FOVEA_UINT width, height, vertical, pad0;
  float sigma_fovea_deg, min_sigma_px, max_sigma_px, cos_skip;  // σ(e) = σ_fovea / m(e) degrees; cos e > cos_skip: σ < min
};

// Temporal error of the display image (recon_temporal.comp): per run of kReconTemporalRun
// pixels of a row the running sum over frames of |Y_t - Y_(t-1)|; accumulate = 0 on the
// first frame (no previous image).
FOVEA_CONST FOVEA_UINT kReconTemporalRun = 64u;
struct ReconTemporalPush {
  FOVEA_UINT width, height, accumulate, pad0;
};

// Grid-space peripheral blur of an angular polar grid (recon_grid_blur.comp): one pass over
// columns [first_column, columns) of the current mapping, across columns (along ρ) or, with
// phi_pass, along the rows of each column; σ in cells from the acuity model and the cells'
// angular size, cells below min_sigma_cells copied.
struct ReconGridBlurPush {
  FOVEA_UINT first_column, phi_pass, pad0, pad1;
  float sigma_fovea_deg, min_sigma_cells, max_sigma_cells, pad2;
};
#ifdef __cplusplus
static_assert(sizeof(ReconGrid) == 192);
static_assert(sizeof(ReconGridBlurPush) == 32);
static_assert(sizeof(ReconAccumulatePush) == 48);
static_assert(sizeof(ReconSharePush) == 32);
static_assert(sizeof(ReconBmfrPush) == 32);
static_assert(sizeof(ReconPostPush) == 32);
static_assert(sizeof(ReconMipPush) == 32);
static_assert(sizeof(ReconResolvePush) == 64);
static_assert(sizeof(ReconBlurPush) == 32);
static_assert(sizeof(ReconTemporalPush) == 16);
}  // namespace fovea::shaders
#else
bool rg_no_sample(float code) { return abs(code - kReconNoSample) < 0.5; }
#endif
#endif
