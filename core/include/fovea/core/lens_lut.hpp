#pragma once
// An optional cache of one eye's forward optics: per colour channel, the source uv at the
// nodes of an N×N grid spanning the panel (node (i, j) at display uv (i, j)/(N − 1)), read
// back by bilinear interpolation. Nodes just beyond a channel's lens edge continue the
// model's profile smoothly (not Lens::source_uv's clamped continuation), so cells at the
// aperture stay accurate for the visible pixels in them. Direct evaluation (Lens::source_uv) stays the reference;
// measure_lut_error gives the cache's error against it (docs/display-stage.md).
#include <array>
#include <vector>

#include <glm/vec2.hpp>

#include "fovea/core/hidden_area.hpp"
#include "fovea/core/lens.hpp"

namespace fovea::core {

class LensLut {
 public:
  static constexpr int kDefaultSize = 128;

  // Throws InputError for size < 2 or > 4096.
  explicit LensLut(const Lens& lens, int size = kDefaultSize);

  int size() const { return n_; }
  // Bilinear interpolation of the nodes; display uv is clamped to the panel. Beyond the
  // lens edge (hidden pixels) it may differ from Lens::source_uv. The shader
  // (lens_distort.comp) interpolates the same way: cell index min(⌊uv·(N−1)⌋, N − 2).
  glm::dvec2 source_uv(int c, glm::dvec2 display_uv) const;
  // Node values for the GPU: float (u, v) pairs at index ((j·N + i)·3 + c)·2.
  std::vector<float> packed() const;

 private:
  int n_ = 0;
  std::vector<glm::dvec2> uv_;  // (j·N + i)·3 + c
};

// The cache's error against direct evaluation over the visible panel pixels (centres of
// every `stride`-th pixel in both axes), per channel.
struct LutError {
  // |cached − direct source position| in pixels of the rendered view (same raster as the panel).
  double max_view_px = 0, mean_view_px = 0;
  // The same error as a displacement on the panel, in display pixels: how far the image
  // moves (the source error mapped back through the inverse of the optics' Jacobian).
  double max_display_px = 0, mean_display_px = 0;
  glm::dvec2 worst_uv{0.5, 0.5};  // display uv of the largest display-pixel error
};
std::array<LutError, 3> measure_lut_error(const LensLut& lut, const HiddenAreaMask& mask, int stride = 1);

}  // namespace fovea::core
