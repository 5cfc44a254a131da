#pragma once
// The hidden area of one eye, derived from its lens (lens.hpp) instead of a fixed octagon.
//
// Display space: a panel pixel is hidden when, at its centre, any colour channel's source
// leaves the rendered FOV or passes the lens edge (cut-off or end of monotonicity); the
// distortion pass writes black there. Stored as a bitmask at display resolution.
// View space: a view direction is visible when some channel shows it at a panel position
// where every channel is inside (inverse optics; the continuous region the bitmask samples
// at pixel centres, so the edges do not alias). This is what applications (XR_KHR_visibility_mask meshes) and
// the path tracer's sample grids skip.
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "fovea/core/lens.hpp"

namespace fovea::core {

class HiddenAreaMask {
 public:
  explicit HiddenAreaMask(const Lens& lens);

  const Lens& lens() const { return lens_; }
  int width() const { return lens_.view().width(); }
  int height() const { return lens_.view().height(); }

  // Display (panel) pixels.
  bool hidden(int x, int y) const { return (bits_[size_t(y) * words_per_row_ + (x >> 5)] >> (x & 31)) & 1u; }
  // Continuous panel position (pixels, origin top-left); off the panel counts as hidden.
  bool hidden_at(glm::dvec2 px) const;
  double hidden_fraction() const { return hidden_fraction_; }
  // Row-major, words_per_row() 32-bit words per row, bit (x & 31) of word x >> 5 set = hidden
  // (the layout a shader reads from a uint buffer).
  std::span<const std::uint32_t> words() const { return bits_; }
  int words_per_row() const { return words_per_row_; }

  // View space: can anyone see this direction (unit or not, view space, −Z forward)?
  bool visible(glm::dvec3 view_dir) const;
  // The same for a continuous position in the rendered view's raster (the sample grids'
  // screen position): pass as SampleDistribution::set_visibility.
  bool visible_view_px(glm::dvec2 view_px) const;

 private:
  Lens lens_;
  int words_per_row_ = 0;
  std::vector<std::uint32_t> bits_;
  double hidden_fraction_ = 0;
};

// XR_KHR_visibility_mask-style meshes in the view's tangent plane (z = −1, x right, y up),
// triangles counter-clockwise as seen by the user. Hidden ∪ visible triangles tile the FOV
// rectangle. The visible region is traced as a polygon around the optical axis (the rays
// from it cross the boundary once for radial optics); segments = its vertex count before the
// four FOV corners' directions are added.
// Whether every channel's source at display uv is inside the FOV and the lens edge.
bool shows_all_channels(const Lens& lens, glm::dvec2 display_uv);

enum class VisibilityMeshType { HiddenTriangles = 1, VisibleTriangles = 2, LineLoop = 3 };

struct VisibilityMesh {
  std::vector<glm::vec2> vertices;
  std::vector<std::uint32_t> indices;  // triangle list, or the loop's vertex order
};

VisibilityMesh visibility_mesh(const HiddenAreaMask& mask, VisibilityMeshType type, int segments = 256);

}  // namespace fovea::core
