#pragma once
// XR_KHR_visibility_mask geometry for one eye, in the view's tangent plane (z = -1, x right,
// y up, counter-clockwise triangles): the lens-derived hidden area of core/hidden_area.hpp.
#include <cstdint>
#include <vector>

#include "fovea/core/hidden_area.hpp"
#include "xr.hpp"

namespace fovea::runtime {

struct VisibilityMask {
  std::vector<XrVector2f> vertices;
  std::vector<std::uint32_t> indices;
};

VisibilityMask visibility_mask(const core::HiddenAreaMask& hidden, XrVisibilityMaskTypeKHR type);

}  // namespace fovea::runtime
