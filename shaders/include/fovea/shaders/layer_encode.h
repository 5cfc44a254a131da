// The API layer's hand-over of a traced eye (layer_encode.comp): the pipeline's displayed
// image encoded for the application's swapchain, on the device, into a traced-frame slot of
// memory the application's device reads. Shared C++/GLSL.
#ifndef FOVEA_SHADERS_LAYER_ENCODE_H
#define FOVEA_SHADERS_LAYER_ENCODE_H
#include "fovea/shaders/common.h"

// Set 0: the displayed image (FramePipeline's screen buffer, vec4 per pixel, row-major) and
// the slots (4-byte words: RGBA8 or BGRA8 pixels).
#define ENCODE_BINDING_SCREEN 0
#define ENCODE_BINDING_SLOTS 1

#ifdef __cplusplus
namespace fovea::shaders {
#endif

FOVEA_CONST FOVEA_UINT kEncodeGroup = 64u;  // the local size in x (a 1-D dispatch over the pixels)

// The display transform of core/tonemap.hpp (ACES, Narkowicz's fit with HDR-FLIP's 0.6 input
// scale), as 32-bit floats: t(x) = (k0·x² + k1·x) / (k3·x² + k4·x + k5).
FOVEA_CONST float kAcesK0 = 0.9036f;  // 0.6²·2.51
FOVEA_CONST float kAcesK1 = 0.018f;   // 0.6·0.03
FOVEA_CONST float kAcesK3 = 0.8748f;  // 0.6²·2.43
FOVEA_CONST float kAcesK4 = 0.354f;   // 0.6·0.59
FOVEA_CONST float kAcesK5 = 0.14f;

struct EncodePush {
  FOVEA_UINT pixels;       // width × height of the eye
  FOVEA_UINT first_word;   // where the eye's colour starts in the slots (in 4-byte words)
  FOVEA_UINT srgb;         // 1: sRGB-encoded swapchain format, 0: linear UNORM
  FOVEA_UINT bgra;         // 1: B8G8R8A8 channel order, 0: R8G8B8A8
};

#ifdef __cplusplus
static_assert(sizeof(EncodePush) == 16);
}  // namespace fovea::shaders
#endif
#endif
