#include "fovea/core/stereo_views.hpp"

#include <glm/gtc/quaternion.hpp>

namespace fovea::core {

std::array<Pose, 2> eye_poses(const Pose& head, double ipd_m, double cant_deg) {
  std::array<Pose, 2> p{head, head};
  p[0].position += head.orientation * glm::dvec3(-0.5 * ipd_m, 0, 0);
  p[1].position += head.orientation * glm::dvec3(0.5 * ipd_m, 0, 0);
  if (cant_deg != 0) {  // the left eye turns left (+y, OpenXR), the right eye right
    const double a = glm::radians(cant_deg);
    p[0].orientation = head.orientation * glm::angleAxis(a, glm::dvec3(0, 1, 0));
    p[1].orientation = head.orientation * glm::angleAxis(-a, glm::dvec3(0, 1, 0));
  }
  return p;
}

std::array<Pose, 2> eye_poses(const Pose& head, const DisplayPreset& d) {
  return eye_poses(head, d.ipd_m, d.cant_deg);
}

StereoViews stereo_views(const DisplayPreset& d, const Pose& head) {
  const std::array<Pose, 2> p = eye_poses(head, d);
  return {{d.view(Eye::Left, p[0]), d.view(Eye::Right, p[1])}, d.ipd_m};
}

}  // namespace fovea::core
