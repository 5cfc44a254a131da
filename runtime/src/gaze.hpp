#pragma once
// The eye tracker behind XR_EXT_eye_gaze_interaction: a combined-eye gaze direction in VIEW
// space, with the time the sample was taken and whether it is valid (blinks are invalid).
#include <memory>
#include <string>

#include <glm/vec3.hpp>

#include "fovea/core/clock.hpp"

namespace fovea::runtime {

struct GazeSample {
  glm::dvec3 dir{0, 0, -1};   // unit, view space (-Z forward)
  bool valid = false;
  core::TimeNs sample_ns = 0;  // when the tracker took the sample (CLOCK_MONOTONIC)
};

class GazeTracker {
 public:
  virtual ~GazeTracker() = default;
  // The tracker's latest sample at or before `t_ns`; `epoch_ns` is the display epoch, the
  // origin of scripted models.
  virtual GazeSample sample_at(core::TimeNs t_ns, core::TimeNs epoch_ns) = 0;
  virtual std::string describe() const = 0;
};

// env FOVEA_GAZE: "synthetic" (default) or "synthetic:<seed>": a built-in deterministic model.
// Throws core::InputError for a spec it cannot serve.
std::unique_ptr<GazeTracker> open_gaze_tracker(const std::string& spec);

}  // namespace fovea::runtime
