// Parameters and output conventions of the grid path tracer (pt_trace.comp). Shared C++/GLSL.
//
// Outputs, one entry per grid cell (index = row * columns + column, like the GridSample
// input), all vec4 of fp32, never NaN/Inf:
//   direct    rgb: demodulated (a) emission + direct lighting + specular-lobe indirect, a: the
//             samples this cell's mean holds this dispatch (spp, or boost_spp in the boosted fovea)
//   indirect  rgb: demodulated (b) diffuse-lobe indirect lighting, a as direct's
//   albedo    rgb: first-hit base colour (textured); 1 for rays that leave the scene; a = 1
//   normal_depth    xyz: world shading normal facing the viewer, w: linear view depth (0 on a miss)
//   position_material xyz: world position, w: material index (-1 on a miss or a skipped cell)
//   radiance  rgb: the cell's linear radiance, not demodulated, a = 1
// Per sample, radiance = max(albedo, kPtMinDemodAlbedo) * (direct + indirect); means over
// several samples (jitter, accumulation) agree only where the albedo is constant. Skipped cells
// (flags != 0) are all zeros with material -1.
#ifndef FOVEA_SHADERS_PT_TRACE_H
#define FOVEA_SHADERS_PT_TRACE_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

// Demodulation divides by max(albedo, this), so black surfaces keep finite values.
FOVEA_CONST float kPtMinDemodAlbedo = 0.01f;
// Bounce limit applied to "unlimited" paths; Russian roulette ends them long before.
FOVEA_CONST FOVEA_UINT kPtHardMaxBounces = 256;

// flags
FOVEA_CONST FOVEA_UINT kPtJitter = 1;      // jitter directions over the cell's footprint
FOVEA_CONST FOVEA_UINT kPtAccumulate = 2;  // running mean with `accumulated_samples` earlier samples
FOVEA_CONST FOVEA_UINT kPtTileOrder = 4;   // invocations take cells in tile order (pt_order.h)
FOVEA_CONST FOVEA_UINT kPtLiveList = 16;   // invocations take the grid pass's live cells (live_cells.h)

// Scene features, specialization constants of pt_trace.comp (constant_id): a variant
// without texture fetches, GGX lobes or light sampling for scenes that do not need them.
FOVEA_CONST FOVEA_UINT kPtSpecTextures = 0;
FOVEA_CONST FOVEA_UINT kPtSpecGlossy = 1;
FOVEA_CONST FOVEA_UINT kPtSpecEmitters = 2;

// Samples per dispatch. lavapipe (gallivm) caps the iterations of all loops nested in one
// outermost loop at 65535 per invocation and silently breaks out beyond, so long
// sample loops are split into several dispatches.
FOVEA_CONST FOVEA_UINT kPtMaxSppPerDispatch = 8;

struct PtFrameParams {
  float rot0_x, rot0_y, rot0_z, origin_x;  // view-to-world rotation (columns) and eye position
  float rot1_x, rot1_y, rot1_z, origin_y;
  float rot2_x, rot2_y, rot2_z, origin_z;
  float env_r, env_g, env_b;
  FOVEA_UINT light_count;
  FOVEA_UINT cell_count, frame, eye, spp;
  FOVEA_UINT max_bounces;  // BSDF-sampled bounces after the primary hit
  FOVEA_UINT rr_start;     // bounce from which Russian roulette applies
  FOVEA_UINT flags;
  FOVEA_UINT accumulated_samples;  // samples already averaged into the outputs (kPtAccumulate)
  float pixel_tx, pixel_ty;         // tangent-plane size of one display pixel (jitter scale)
  FOVEA_UINT sample_offset;         // index of this dispatch's first sample in the frame (RNG key)
  FOVEA_UINT columns;               // the grid's padded column count (kPtTileOrder)
  FOVEA_UINT boost_spp;             // cells within boost_deg of the gaze trace this many samples (0: none)
  float boost_deg;
  float texture_cone;  // > 0: first hits read the texture mip level of a cone this many cells wide
};

#ifdef __cplusplus
static_assert(sizeof(PtFrameParams) == 124);
}  // namespace fovea::shaders
#endif
#endif
