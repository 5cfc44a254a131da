#include "gaze_hold.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace fovea::layer {

glm::dvec3 GazeHold::update(std::int64_t t_ns, bool tracked, glm::dvec3 dir) {
  const glm::dvec3 fixed(0, 0, -1);
  if (tracked && std::isfinite(dir.x) && std::isfinite(dir.y) && std::isfinite(dir.z) && glm::length(dir) > 0) {
    last_ = glm::normalize(dir);
    last_ns_ = t_ns;
    seen_ = true;
    return last_;
  }
  if (!seen_) return fixed;
  const std::int64_t lost = t_ns - last_ns_;
  if (lost <= kHoldNs) return last_;
  // Smoothstep from the held gaze to the forward direction (no jump, no overshoot).
  const double u = std::clamp(double(lost - kHoldNs) / double(kEaseNs), 0.0, 1.0);
  const double w = u * u * (3 - 2 * u);
  const glm::dvec3 d = (1 - w) * last_ + w * fixed;
  return glm::length(d) > 1e-9 ? glm::normalize(d) : fixed;
}

}  // namespace fovea::layer
