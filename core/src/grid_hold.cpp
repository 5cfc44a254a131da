#include "fovea/core/grid_hold.hpp"

#include <cmath>

#include <glm/geometric.hpp>

#include "fovea/core/view.hpp"

namespace fovea::core {

glm::dvec3 GridHold::place(const glm::dvec3& gaze) {
  if (!std::isfinite(gaze.x) || !std::isfinite(gaze.y) || !std::isfinite(gaze.z)) return gaze;
  if (glm::length(held_) > 0 && angle_deg(gaze, held_) < radius_deg_) return held_;
  held_ = gaze;
  return gaze;
}

}  // namespace fovea::core
