#pragma once
// The eye tracker behind XR_EXT_eye_gaze_interaction: the devices foveation gaze over a
// source URI (env FOVEA_GAZE, default "synthetic:1"; e.g. "replay:FILE",
// "synthetic:SEED?task=reading", "hid:") on the runtime's clock. Recorded and synthetic
// sources start at the display epoch, so a run sees the same gaze at the same frame index
// every time; live ones run on the host monotonic clock (the source says which it is).
// The application gets the tracker's own measurement: no hold, a blink or a loss is invalid.
#include <memory>
#include <string>

#include <glm/vec3.hpp>

#include "fovea/core/clock.hpp"
#include "fovea/core/display.hpp"

namespace fovea::devices {
class FoveationGaze;
}

namespace fovea::runtime {

struct GazeSample {
  glm::dvec3 dir{0, 0, -1};    // combined gaze, unit, view space (-Z forward)
  bool valid = false;          // tracked (not a blink, dropout, stale or low confidence)
  // The newest real sample used (never the time asked for; 0 when none was measured yet),
  // when the host received it and when the runtime read it (CLOCK_MONOTONIC).
  core::TimeNs sample_ns = 0, receive_ns = 0, read_ns = 0;
};

class GazeTracker {
 public:
  // Throws core::InputError for a URI the devices module cannot open.
  GazeTracker(const std::string& uri, const core::DisplayPreset& display);
  ~GazeTracker();
  GazeTracker(const GazeTracker&) = delete;
  GazeTracker& operator=(const GazeTracker&) = delete;

  // The gaze at time t_ns from the samples measured by then; `epoch_ns` is where recorded
  // and synthetic sources start.
  GazeSample sample_at(core::TimeNs t_ns, core::TimeNs epoch_ns);
  std::string describe() const;

 private:
  std::unique_ptr<devices::FoveationGaze> gaze_;
};

}  // namespace fovea::runtime
