// The API layer's composition on the application's device (xr_layer_composite.comp): per eye,
// the path-traced frame reprojected by rotation into the submitted view and the application's
// pixels composited over it, as the layer's host path does (layer/src/composite.cpp). Pixels
// are 4 bytes packed in a uint, in the swapchain's channel order and encoding. Shared C++/GLSL.
#ifndef FOVEA_SHADERS_LAYER_COMPOSITE_H
#define FOVEA_SHADERS_LAYER_COMPOSITE_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
namespace fovea::shaders {
#endif

// The bindings of set 0 (storage buffers; the parameters' with a dynamic offset: each pass
// reads its own block).
#define LAYER_BINDING_PARAMS 0
#define LAYER_BINDING_TRACED 1
#define LAYER_BINDING_APP 2
#define LAYER_BINDING_OUT 3
#define LAYER_BINDING_BACKGROUND 4
#define LAYER_BINDING_APP_DEPTH 5
#define LAYER_BINDING_COUNT 6

// LayerCompositeParams.mode (layer::Composite)
FOVEA_CONST FOVEA_UINT kLayerAppOnTop = 0u;
FOVEA_CONST FOVEA_UINT kLayerAlpha = 1u;
FOVEA_CONST FOVEA_UINT kLayerSceneOnly = 2u;
// By depth (the application chained XrCompositionLayerDepthInfoKHR): the application's pixel
// where its surface is nearer than the traced scene's (composite_depth in composite.hpp).
FOVEA_CONST FOVEA_UINT kLayerDepth = 3u;
// LayerCompositeEye.depth_format: how the application's depth texels are packed by a buffer
// copy of the depth aspect.
FOVEA_CONST FOVEA_UINT kLayerDepthD16 = 1u;   // 16-bit UNORM, two per word
FOVEA_CONST FOVEA_UINT kLayerDepthD24 = 2u;   // 24-bit UNORM in the low bits of a word
FOVEA_CONST FOVEA_UINT kLayerDepthD32F = 3u;  // float (non-finite: the far plane)
// Specialisation constant 0, the pass: the border pass finds AppOnTop's background (the most
// frequent colour on the application image's border, one workgroup per eye), the composite
// pass writes out. Push constant: the eye.
FOVEA_CONST FOVEA_UINT kLayerPassBorder = 0u;
FOVEA_CONST FOVEA_UINT kLayerPassComposite = 1u;
FOVEA_CONST FOVEA_UINT kLayerBorderGroup = 64u;
// The composite pass: each invocation writes this many rows of its column.
FOVEA_CONST FOVEA_UINT kLayerRowsPerInvocation = 16u;

// One eye. A view is its tangent-plane extents at z = -1 (left, right, up, down) and raster;
// a direction of the output view turns into the traced view's by `to_traced` (row-major 3x3,
// conj(q_traced) * q_submitted). `*_identity`: the host path copies without resampling
// (same FOV and raster, no rotation), so the shader does too.
struct LayerCompositeEye {
  float out_tan[4];
  float traced_tan[4];
  float to_traced[9];
  FOVEA_INT out_w, out_h, traced_w, traced_h, app_w, app_h;
  FOVEA_UINT traced_offset, app_offset, out_offset;  // in pixels, into the three buffers
  FOVEA_UINT traced_identity, app_identity;
  // kLayerDepth: the traced frame's view distances follow both eyes' colour in Traced
  // (`traced_depth_offset`, floats); the application's window depths are in AppDepth at byte
  // `depth_offset` (a multiple of 4) in `depth_format`, mapped to distances by their range
  // (XrCompositionLayerDepthInfoKHR: minDepth at nearZ, maxDepth at farZ; 1/plane, 0 at infinity).
  FOVEA_UINT traced_depth_offset, depth_format, depth_offset;
  float min_depth, max_depth, inv_near, inv_far;
};

struct LayerCompositeParams {
  LayerCompositeEye eye[2];
  FOVEA_UINT mode;
  FOVEA_UINT auto_background;  // AppOnTop: 1 = the border pass's colour, 0 = `background`
  FOVEA_UINT background;       // packed bytes 0..2
  FOVEA_INT tolerance;         // AppOnTop: a channel differing by more keeps the application's pixel
  FOVEA_UINT source_alpha, premultiplied, srgb, pad;
  float decode[256];  // 8-bit channel -> linear (the host's table, so both decode alike)
};

#ifdef __cplusplus
static_assert(sizeof(LayerCompositeEye) == 140);
static_assert(sizeof(LayerCompositeParams) == 2 * 140 + 32 + 256 * 4);
}  // namespace fovea::shaders
#endif
#endif
