#include "visibility_mask.hpp"

#include <cmath>

namespace fovea::runtime {

const char* visibility_mask_source() { return "rectangular field of view (no lens model)"; }

VisibilityMask visibility_mask(const core::DisplayPreset& display, core::Eye eye, XrVisibilityMaskTypeKHR type) {
  const core::Fov& f = display.fov(eye);
  const float l = float(std::tan(f.angle_left)), r = float(std::tan(f.angle_right));
  const float u = float(std::tan(f.angle_up)), d = float(std::tan(f.angle_down));
  VisibilityMask m;
  switch (type) {
    case XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR: break;
    case XR_VISIBILITY_MASK_TYPE_VISIBLE_TRIANGLE_MESH_KHR:
      m.vertices = {{l, d}, {r, d}, {r, u}, {l, u}};
      m.indices = {0, 1, 2, 0, 2, 3};
      break;
    case XR_VISIBILITY_MASK_TYPE_LINE_LOOP_KHR:
      m.vertices = {{l, d}, {r, d}, {r, u}, {l, u}};
      m.indices = {0, 1, 2, 3};
      break;
    default: break;
  }
  return m;
}

}  // namespace fovea::runtime
