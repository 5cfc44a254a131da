#pragma once
// Display pixels' first hits (pt_primary.comp): for a window of an eye's display raster
// around the gaze, rays through the strata of each pixel and their first hits' mean base
// colour (textured, together the pixel's box filter) and material. The reconstruction re-modulates the
// fovea with them, so that textures there keep the display's resolution where the grid's
// cells, which are not the display's pixels, would blur them once more in the resolve
// (docs/reconstruction.md, "Textures at the display's resolution").
#include <cstdint>

#include <glm/vec3.hpp>

#include "fovea/core/view.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/renderer/gpu_scene.hpp"

namespace fovea::renderer {

// A rectangle of display pixels, [x0, x0 + width) × [y0, y0 + height).
struct PixelWindow {
  std::uint32_t x0 = 0, y0 = 0, width = 0, height = 0;
  std::uint32_t pixels() const { return width * height; }
  bool empty() const { return width == 0 || height == 0; }
};

// The display pixels whose centres' rays can lie within `radius_deg` of `axis` (a view-space
// direction): the bounding box of the cone's trace on the raster, one pixel wider each way,
// clipped to the raster (empty where the cone misses it or `axis` is not finite). At most
// `max_pixels`: a larger box is cropped to max_pixels around the axis' pixel.
PixelWindow cone_window(const core::View& view, glm::dvec3 axis, double radius_deg, std::uint32_t max_pixels);
// The most pixels cone_window gives for `radius_deg` anywhere within 60° of the view's axis
// (beyond, on very wide rasters, the window is cropped), at most the raster.
std::uint32_t cone_window_capacity(const core::View& view, double radius_deg);

// The first hits of one window's pixels: one vec4 per pixel (pt_primary.h), row by row.
class PrimaryHits {
 public:
  const gpu::Buffer& hits() const { return hits_; }
  std::uint32_t capacity() const { return capacity_; }

 private:
  friend class DisplayAlbedo;
  std::uint32_t capacity_ = 0;
  gpu::Buffer hits_;
  gpu::DescriptorSet set_;
};

// Rays per pixel along each axis: the grazing bricks' fovea SSIM / HDR-FLIP at 16 ppd (the
// pipeline tests' GrazingTexture, still gaze) was 0.862 / 0.258 with one ray per pixel (point
// samples alias the mortar into moiré), 0.948 / 0.177 with 2 × 2, 0.972 / 0.150 with 3 × 3
// (the display's own raster: 0.987 / 0.120), for 13 and 29 ms of a `fove0` frame of about
// 1100 ms on lavapipe (docs/reconstruction.md, "Textures at the display's resolution").
inline constexpr std::uint32_t kPixelAlbedoGrid = 3;

class DisplayAlbedo {
 public:
  explicit DisplayAlbedo(gpu::Context& ctx, const GpuScene& scene);

  // Whether the scene's base colours vary within a material (textures): else every pixel
  // has its material's base colour, which the grid's cells hold already.
  bool needed() const { return scene_.features().textures; }
  PrimaryHits bind(std::uint32_t capacity) const;
  // Records the first hits of `window`'s pixels of `view`'s raster (its pose: the eye's)
  // into `out` (window.pixels() ≤ its capacity): `grid` × `grid` rays per pixel (1 to 4), each
  // with a texture cone of `texture_cone` times its stratum. The caller orders later reads with a barrier.
  void record(VkCommandBuffer cmd, PrimaryHits& out, const core::View& view, const PixelWindow& window,
              std::uint32_t grid = kPixelAlbedoGrid, double texture_cone = 1.0) const;

 private:
  gpu::Context& ctx_;
  const GpuScene& scene_;
  gpu::ComputePipeline pipeline_;
};

}  // namespace fovea::renderer
