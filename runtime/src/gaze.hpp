#pragma once
// The eye tracker behind XR_EXT_eye_gaze_interaction: a devices::GazeSource (env FOVEA_GAZE,
// default "synthetic:1"; e.g. "replay:FILE", "synthetic:SEED?task=reading", "hid:") adapted
// to the runtime's clock. Recorded and synthetic sources count time from their first
// sample; the runtime starts them at the display epoch, so a run sees the same gaze at the
// same frame index every time. Live sources already use the host monotonic clock.
#include <memory>
#include <string>

#include <glm/vec3.hpp>

#include "fovea/core/clock.hpp"
#include "fovea/core/display.hpp"

namespace fovea::devices {
class GazeSource;
}

namespace fovea::runtime {

struct GazeSample {
  glm::dvec3 dir{0, 0, -1};    // combined gaze, unit, view space (-Z forward)
  bool valid = false;          // tracked (not a blink, dropout or low confidence)
  core::TimeNs sample_ns = 0;  // the sample's time (CLOCK_MONOTONIC)
};

class GazeTracker {
 public:
  // Throws core::InputError for a URI the devices module cannot open.
  GazeTracker(const std::string& uri, const core::DisplayPreset& display);
  ~GazeTracker();
  GazeTracker(const GazeTracker&) = delete;
  GazeTracker& operator=(const GazeTracker&) = delete;

  // The gaze at time t_ns; `epoch_ns` is where recorded/synthetic sources start.
  GazeSample sample_at(core::TimeNs t_ns, core::TimeNs epoch_ns);
  std::string describe() const;

 private:
  std::unique_ptr<devices::GazeSource> source_;
  bool live_ = false;
};

}  // namespace fovea::runtime
