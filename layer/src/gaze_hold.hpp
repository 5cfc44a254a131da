#pragma once
// What the foveation follows when the tracker loses the eye: the last tracked gaze is held
// for kHoldNs (a blink or a short dropout should not move the fovea), then the gaze eases
// over kEaseNs to fixed foveation (the view's forward direction), and snaps back to the
// tracker when it returns.
#include <cstdint>

#include <glm/vec3.hpp>

namespace fovea::layer {

class GazeHold {
 public:
  static constexpr std::int64_t kHoldNs = 600'000'000;
  static constexpr std::int64_t kEaseNs = 400'000'000;

  // One update at time t_ns (monotonic): `tracked` says whether `dir` (unit, view space)
  // is a measurement. Returns the direction to foveate.
  glm::dvec3 update(std::int64_t t_ns, bool tracked, glm::dvec3 dir);

 private:
  glm::dvec3 last_{0, 0, -1};
  std::int64_t last_ns_ = 0;
  bool seen_ = false;
};

}  // namespace fovea::layer
