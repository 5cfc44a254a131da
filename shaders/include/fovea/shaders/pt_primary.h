// Display pixels' first hits (pt_primary.comp): for a window of an eye's display raster, rays
// through the strata of each pixel, and their first hits' base colour and material. The
// reconstruction re-modulates the fovea with them (recon_resolve.comp: textures at the
// display's resolution where the grid's cells are about a pixel). Shared C++/GLSL.
//
// Output, one vec4 per window pixel (index = (y - y0) * width + (x - x0)), never NaN/Inf:
//   rgb: the mean base colour of the pixel's rays' first hits (textured, each prefiltered
//        over its ray's share of the pixel; 0 on a back face that is not lit), a: the material
//        index of the first hit of the ray nearest the centre, kPtPrimaryNoHit on its miss.
#ifndef FOVEA_SHADERS_PT_PRIMARY_H
#define FOVEA_SHADERS_PT_PRIMARY_H
#include "fovea/shaders/common.h"

// pt_primary.comp, set 0 (the BVH's bindings as pt_trace.comp's, then these)
#define PRIMARY_BINDING_SHADING 2    // texel buffer, PtShading: 4 texels each
#define PRIMARY_BINDING_MATERIALS 3  // texel buffer, PtMaterial: 3 texels each
#define PRIMARY_BINDING_TEX_TABLE 4  // PtTextureInfo per texture
#define PRIMARY_BINDING_TEXELS 5     // texel buffer, RGBA8 per texel
#define PRIMARY_BINDING_OUT 6        // the window's pixels (above)
#define PRIMARY_BINDING_COUNT 7

#ifdef __cplusplus
namespace fovea::shaders {
#endif

FOVEA_CONST float kPtPrimaryNoHit = -1.0f;

struct PtPrimaryParams {
  float rot0_x, rot0_y, rot0_z, origin_x;  // view-to-world rotation (columns) and eye position
  float rot1_x, rot1_y, rot1_z, origin_y;
  float rot2_x, rot2_y, rot2_z, origin_z;
  float tan_left, tan_up;    // tangent-plane position of the raster's top-left corner
  float pixel_tx, pixel_ty;  // tangent-plane size of one display pixel
  FOVEA_UINT x0, y0, width, height;  // the window (display pixels)
  float texture_cone;        // the first hit's texture cone, in pixels
  FOVEA_UINT grid;           // grid × grid rays per pixel, at the centres of its strata
  FOVEA_UINT pad1, pad2;
};

#ifdef __cplusplus
static_assert(sizeof(PtPrimaryParams) == 96);
}  // namespace fovea::shaders
#endif
#endif
