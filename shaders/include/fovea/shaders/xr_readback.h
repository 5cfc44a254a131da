// The runtime compositor's read of a submitted swapchain image (xr_readback.comp): its
// bindings, push constants and workgroup. Shared C++/GLSL.
#ifndef FOVEA_SHADERS_XR_READBACK_H
#define FOVEA_SHADERS_XR_READBACK_H
#include "fovea/shaders/common.h"

// Set 0: the swapchain image's view (a combined image sampler) and the texels read.
#define READBACK_BINDING_SOURCE 0
#define READBACK_BINDING_OUT 1

#ifdef __cplusplus
namespace fovea::shaders {
#endif

FOVEA_CONST FOVEA_UINT kReadbackGroup = 8u;  // the local size in x and y

// The push constants: the rectangle read (offset and size) and the array layer.
struct ReadbackPush {
  FOVEA_INT offset_x;
  FOVEA_INT offset_y;
  FOVEA_UINT width;
  FOVEA_UINT height;
  FOVEA_UINT layer;
};

#ifdef __cplusplus
static_assert(sizeof(ReadbackPush) == 20);
}  // namespace fovea::shaders
#endif
#endif
