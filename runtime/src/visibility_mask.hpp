#pragma once
// XR_KHR_visibility_mask geometry for one eye, in the view's tangent plane (z = -1).
// Without a lens model the whole rectangular field of view is visible: the hidden mesh is
// empty, the visible mesh is the FOV rectangle (two counter-clockwise triangles) and the line
// loop is its outline.
#include <cstdint>
#include <vector>

#include "fovea/core/display.hpp"
#include "xr.hpp"

namespace fovea::runtime {

struct VisibilityMask {
  std::vector<XrVector2f> vertices;
  std::vector<std::uint32_t> indices;
};

VisibilityMask visibility_mask(const core::DisplayPreset& display, core::Eye eye, XrVisibilityMaskTypeKHR type);
// Where the mask comes from, for logs and reports.
const char* visibility_mask_source();

}  // namespace fovea::runtime
