#pragma once
// The eye tracker behind XR_EXT_eye_gaze_interaction: the devices foveation gaze over a
// source URI (env FOVEA_GAZE, default "synthetic:1"; e.g. "replay:FILE",
// "synthetic:SEED?task=reading", "hid:") on the runtime's clock. Recorded and synthetic
// sources start at the display epoch, so a run sees the same gaze at the same frame index
// every time; live ones run on the host monotonic clock (the source says which it is).
// The application gets the tracker's own measurement: no hold, a blink or a loss is invalid.
#include <memory>
#include <optional>
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
  // when the host received it, and the read time: the samples delivered by then were
  // available (CLOCK_MONOTONIC; sample_ns <= receive_ns <= read_ns).
  core::TimeNs sample_ns = 0, receive_ns = 0, read_ns = 0;
};

class GazeTracker {
 public:
  // Throws core::InputError for a URI the devices module cannot open.
  GazeTracker(const std::string& uri, const core::DisplayPreset& display);
  ~GazeTracker();
  GazeTracker(const GazeTracker&) = delete;
  GazeTracker& operator=(const GazeTracker&) = delete;

  // The gaze for target_ns (a display time, a located time) as read at read_ns: the newest
  // sample delivered by min(read_ns, target_ns), never a later one (so sample_ns <= read_ns),
  // predicted to target_ns from the delivered samples when the source predicts (URI key
  // predict=). `epoch_ns` is where recorded and synthetic sources start.
  GazeSample read(core::TimeNs read_ns, core::TimeNs target_ns, core::TimeNs epoch_ns);
  // The true gaze (combined, view space) at t: a recording's or synthetic gaze's own sample,
  // without the tracker model's delay and noise; none for a live source or an untracked
  // true eye (a blink).
  std::optional<glm::dvec3> truth_at(core::TimeNs t, core::TimeNs epoch_ns);
  std::string describe() const;

 private:
  std::unique_ptr<devices::FoveationGaze> gaze_;
};

}  // namespace fovea::runtime
