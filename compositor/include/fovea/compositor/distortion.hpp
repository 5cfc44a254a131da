#pragma once
// The distortion pass: for each display (panel) pixel, one bilinear tap of the resolved
// view image per colour channel at that channel's source position (core/lens.hpp);
// hidden-area pixels (core/hidden_area.hpp) and taps outside the view are black; the
// result is encoded linear → sRGB explicitly, so every device gives the same bytes.
// The GPU pass evaluates the optics directly per pixel (float32) or, optionally, reads them
// from a 128² LUT cache (core/lens_lut.hpp); distort_reference is the double-precision CPU
// reference it is tested against.
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "fovea/core/hidden_area.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/lens.hpp"
#include "fovea/core/lens_lut.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/image.hpp"
#include "fovea/gpu/pipeline.hpp"

namespace fovea::compositor {

// Which channels' optics to use: all (chromatic aberration) or one channel's map for all
// three (a picture of that channel's distortion).
enum class ChannelSelect : std::uint32_t { All = 3, Red = 0, Green = 1, Blue = 2 };

// How the pass gets each pixel's source positions: the optics evaluated directly (the
// reference), or bilinear reads of a LensLut of LensLut::kDefaultSize² nodes.
enum class OpticsEval { Direct, Lut };

// What a panel receives: 8-bit sRGB RGBA, row-major, top row first.
struct PanelImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  // Linear-light floats (sRGB decoded), e.g. for core::write_png.
  core::Image to_image() const;
};

// CPU reference in linear light (not yet encoded). `view_image` has the view's raster;
// non-finite texels count as black, values are clamped to [0, 1]. With `lut` the source
// positions come from the cache instead of direct evaluation.
core::Image distort_reference(const core::HiddenAreaMask& mask, const core::Image& view_image,
                              ChannelSelect select = ChannelSelect::All, const core::LensLut* lut = nullptr);

// A linear view-space reference image: lines every `step_deg` of angle along both axes
// (the two through the view axis yellow) on a dark background, i.e. a grid of directions
// as a straight-ahead scene would show it; for pictures of the distortion and the mirror.
core::Image direction_grid(const core::View& view, double step_deg = 5);

class DistortionPass {
 public:
  DistortionPass(gpu::Context& ctx, const core::HiddenAreaMask& mask, ChannelSelect select = ChannelSelect::All,
                 OpticsEval eval = OpticsEval::Direct);

  int width() const { return width_; }
  int height() const { return height_; }

  // Records the pass: `source` is an RGBA32F storage image of the view's raster,
  // `target` an RGBA8_UNORM storage image of the panel's raster. The caller orders
  // writes of `source` before it and reads of `target` after it (gpu/barriers.hpp).
  void record(VkCommandBuffer cmd, const gpu::Image2D& source, const gpu::Image2D& target);
  // Upload, run, download: convenient for tools and tests.
  PanelImage run(const core::Image& view_image);

 private:
  gpu::Context* ctx_;
  int width_, height_;
  ChannelSelect select_;
  gpu::ComputePipeline pipeline_;
  gpu::Buffer optics_, mask_, lut_;
  std::uint32_t words_per_row_ = 0, lut_size_ = 0;
  std::vector<std::unique_ptr<gpu::DescriptorSet>> sets_;  // one per (source, target) pair seen
  std::vector<std::pair<VkImageView, VkImageView>> set_keys_;
};

}  // namespace fovea::compositor
