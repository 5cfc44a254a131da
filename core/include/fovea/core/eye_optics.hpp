#pragma once
// One eye's optics for the display stage: the rendered view, the lens and its hidden area,
// and on request the view-space visibility mask the sample grids skip; plus the gaze conversions between
// panel positions and view directions.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "fovea/core/display.hpp"
#include "fovea/core/hidden_area.hpp"
#include "fovea/core/lens.hpp"

namespace fovea::core {

// Hidden view pixels of a rendered view (not panel pixels): bit set = no panel pixel shows
// the view pixel's centre (HiddenAreaMask::visible_view_px). Row-major, row-padded to whole
// 32-bit words (bit x & 31 of word y·words_per_row + x / 32): the layout
// shaders/grid_generate.comp reads, so the GPU grid and a CPU distribution using
// visible_at() skip exactly the same cells.
class ViewMask {
 public:
  ViewMask() = default;
  explicit ViewMask(const HiddenAreaMask& hidden);
  // A runtime's XR_KHR_visibility_mask hidden triangle mesh (vertices in the view's tangent
  // plane z = −1, x right, y up; a triangle list) rasterised into `view`'s raster: a pixel is
  // hidden when its centre lies in (or on the edge of) a triangle of either winding.
  // Throws InputError naming `what` for an index out of range, an index count that is not a
  // multiple of three, or a non-finite vertex.
  static ViewMask from_hidden_triangles(const View& view, std::span<const glm::vec2> vertices,
                                        std::span<const std::uint32_t> indices, const char* what);

  int width() const { return width_; }
  int height() const { return height_; }
  int words_per_row() const { return words_per_row_; }
  std::span<const std::uint32_t> words() const { return bits_; }
  bool hidden(int x, int y) const { return (bits_[std::size_t(y) * words_per_row_ + (x >> 5)] >> (x & 31)) & 1u; }
  // A continuous view position (pixels) is visible when its pixel is; positions beyond the
  // raster are clamped to the border pixel, as the shader does.
  bool visible_at(glm::dvec2 px) const;
  double hidden_fraction() const { return hidden_fraction_; }

 private:
  ViewMask(int width, int height);
  int width_ = 0, height_ = 0, words_per_row_ = 0;
  std::vector<std::uint32_t> bits_;
  double hidden_fraction_ = 0;
};

class EyeOptics {
 public:
  explicit EyeOptics(const Lens& lens);
  EyeOptics(const DisplayPreset& d, Eye e) : EyeOptics(Lens::for_eye(d, e)) {}

  const View& view() const { return hidden_.lens().view(); }
  const Lens& lens() const { return hidden_.lens(); }
  const HiddenAreaMask& hidden() const { return hidden_; }
  // Built on each call (up to three inverse lens solves per view pixel, seconds on the large
  // presets): callers that cull keep the result, the display stage alone never pays for it.
  ViewMask view_mask() const { return ViewMask(hidden_); }

 private:
  HiddenAreaMask hidden_;
};

// The view direction an eye looks along when it looks at a panel position: the green
// channel's forward optics (OpenXR view space, −Z forward).
glm::dvec3 gaze_direction(const Lens& lens, glm::dvec2 panel_uv);
// The panel position that shows a view direction (green channel's inverse optics), or
// nullopt when it is not shown anywhere on the panel.
std::optional<glm::dvec2> gaze_panel_uv(const Lens& lens, glm::dvec3 dir);

}  // namespace fovea::core
