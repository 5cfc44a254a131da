#pragma once
// Combining the path-traced scene with the application's own pixels, on the host (the GPU
// path, xr_layer_composite.comp, repeats these steps on the application's device). Pixels are
// kept in the 8-bit encoding of the application's swapchain (so the application's pixels pass
// through bit-exact wherever they are kept); blending decodes to linear and re-encodes.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <vulkan/vulkan.h>
#include <openxr/openxr.h>

#include "config.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/view.hpp"

namespace fovea::layer {

// The colour formats the layer composites (the runtime's colour swapchain formats).
struct PixelFormat {
  bool bgra = false;  // B8G8R8A8 channel order
  bool srgb = false;  // sRGB-encoded (else linear UNORM)
};
// Throws std::runtime_error for any other format.
PixelFormat pixel_format(VkFormat f);

// Tightly packed 4-byte pixels in a swapchain's channel order, top row first.
struct Pixels8 {
  int width = 0, height = 0;
  std::vector<std::uint8_t> data;
  std::uint8_t* at(int x, int y) { return &data[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4]; }
  const std::uint8_t* at(int x, int y) const {
    return &data[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
  }
};

// Tone-mapped linear radiance (the ACES fit `fovea render` shows, renderer::tone_map) encoded for `fmt`, alpha 1.
Pixels8 encode_scene(const core::Image& linear, PixelFormat fmt);

// The most frequent colour (first three bytes) among the border pixels: the application's
// clear colour when it draws content away from the edges.
std::array<std::uint8_t, 3> border_colour(const Pixels8& img);

// The image `app` (seen through `app_view`) resampled (nearest, by direction) into
// `scene_view`'s raster; `scene_to_app` turns a direction of `scene_view` into one of
// `app_view` (a rotational reprojection: conj(app orientation) * scene orientation, the
// orientations in one space). Identity when both views and the rotation are. Pixels the
// image did not cover get alpha 0.
Pixels8 resample(const Pixels8& app, const core::View& app_view, const core::View& scene_view,
                 const glm::dquat& scene_to_app = glm::dquat(1, 0, 0, 0));
// Whether resample() returns a `width` x `height` image unchanged (same FOV and raster, a
// rotation that moves no pixel).
bool resample_copies(const core::View& app_view, int width, int height, const core::View& scene_view,
                     const glm::dquat& scene_to_app = glm::dquat(1, 0, 0, 0));

// How the application's projection layer blends over what lies below it, from its
// XrCompositionLayerFlags (OpenXR 1.0 "Composition Layer Blending"): without
// XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT the layer is opaque; with it, colour is
// premultiplied by alpha unless XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT is set.
struct LayerBlend {
  bool source_alpha = false;
  bool premultiplied = true;
  bool srgb = false;  // the swapchain stores sRGB-encoded colour: blend after decoding
};
LayerBlend layer_blend(XrCompositionLayerFlags flags, PixelFormat fmt);

// Composites `app` (same raster as `scene`) into `scene` by `mode`. AppOnTop keeps the
// application's pixel where any channel differs from `background` by more than `tolerance`
// (8-bit units); Alpha blends the application's layer over the scene as `blend` says, in
// linear colour. Returns how many pixels show the application.
std::int64_t composite(Pixels8& scene, const Pixels8& app, Composite mode, std::array<std::uint8_t, 3> background,
                       const LayerBlend& blend, int tolerance = 2);

// The mapping of the application's depth values (XrCompositionLayerDepthInfoKHR): window
// depth min_depth lies at view distance near_z, max_depth at far_z. near_z > far_z is
// reversed Z; either plane may be +infinity (an infinite far plane).
struct DepthRange {
  float min_depth = 0, max_depth = 1;
  float near_z = 0.1f, far_z = 100;
};

// One eye of a frame's composition: the traced frame (in `traced_view`'s raster) reprojected
// by rotation into `out_view` (the submitted FOV at the traced raster; `to_traced` =
// conj(q_traced) * q_submitted), opaque black where it does not reach, then the application's
// pixels (`app`, seen through `app_view`: the submitted FOV at its rect's size) composited over
// it. The host path runs it on the CPU, the GPU path (gpu_composite.hpp) the same steps in a
// compute pass on the application's device.
struct EyeComposition {
  const Pixels8* traced = nullptr;
  core::View traced_view, out_view;
  glm::dquat to_traced{1, 0, 0, 0};
  const Pixels8* app = nullptr;  // null: the scene only
  core::View app_view;
  // Compositing by depth (composite_depth) instead of the rule, when both are set with `app`:
  // the traced frame's view distances (traced_view's raster, FramePipeline::depth), reprojected
  // with its colour, and the application's window depths (app_view's raster) with their range.
  const std::vector<float>* traced_depth = nullptr;
  const std::vector<float>* app_depth = nullptr;
  DepthRange depth_range;
  bool by_depth() const { return app && traced_depth && app_depth; }
};
// How the application's pixels are combined: the configured mode, AppOnTop's background
// (unset: border_colour() of the application's image), the layer flags' blending.
struct CompositionRule {
  Composite mode = Composite::AppOnTop;
  std::optional<std::array<std::uint8_t, 3>> background;
  LayerBlend blend;
};
// The traced frame reprojected into out_view, alpha 255 everywhere.
Pixels8 reproject_traced(const EyeComposition& eye);
// reproject_traced, then composite_depth() when eye.by_depth(), else composite() by `rule`
// (the scene alone without `app`).
Pixels8 compose_eye(const EyeComposition& eye, const CompositionRule& rule);

// View-space distance along -Z of window depth `d` under a perspective projection: its
// normalised depth t = (d - min_depth) / (max_depth - min_depth) is affine in 1/z,
// 1/z = (1 - t)/near_z + t/far_z. +infinity at an infinite plane; throws std::runtime_error
// for a degenerate range (equal depths or planes, a plane <= 0).
double view_distance(float d, const DepthRange& range);

// Keeps the application's pixel where its surface is nearer than the scene's. `app_depth`
// holds the application's window depths (same raster as `app`), `scene_depth` the scene's
// view distances along -Z (FramePipeline::depth: 0 = nothing at a finite distance). Pixels
// where the application left its depth at the far plane (cleared, drew nothing) or its
// alpha at 0 keep the scene. Returns how many pixels show the application.
std::int64_t composite_depth(Pixels8& scene, const std::vector<float>& scene_depth, const Pixels8& app,
                             const std::vector<float>& app_depth, const DepthRange& range);

// Per-pixel floats (depths) resampled like resample() moves pixels; 0 where not covered.
std::vector<float> resample_depth(const std::vector<float>& depth, const core::View& from, const core::View& to,
                                  const glm::dquat& to_from = glm::dquat(1, 0, 0, 0));

}  // namespace fovea::layer
