#include "fovea/core/stereo_views.hpp"

namespace fovea::core {

std::array<Pose, 2> eye_poses(const Pose& head, double ipd_m) {
  std::array<Pose, 2> p{head, head};
  p[0].position += head.orientation * glm::dvec3(-0.5 * ipd_m, 0, 0);
  p[1].position += head.orientation * glm::dvec3(0.5 * ipd_m, 0, 0);
  return p;
}

StereoViews stereo_views(const DisplayPreset& d, const Pose& head) {
  const std::array<Pose, 2> p = eye_poses(head, d.ipd_m);
  return {{d.view(Eye::Left, p[0]), d.view(Eye::Right, p[1])}, d.ipd_m};
}

}  // namespace fovea::core
