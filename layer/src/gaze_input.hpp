#pragma once
// The layer's gaze for each frame: the eye-gaze action's measurement when the runtime offers
// XR_EXT_eye_gaze_interaction, else the configured devices source (FOVEA_GAZE); both through
// the one foveation gaze (devices/foveation_gaze.hpp: time base, loss policy, true times).
#include <cstdint>
#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "fovea/core/display.hpp"
#include "fovea/devices/foveation_gaze.hpp"

namespace fovea::layer {

// The eye-gaze action located at a frame's display time: the gaze in VIEW space (nullopt:
// not tracked) and the time of the tracker sample it came from (XrEyeGazeSampleTimeEXT;
// 0 when the runtime did not report one).
struct ActionGaze {
  std::optional<glm::dvec3> dir;
  std::int64_t sample_time_ns = 0;
};

class LayerGaze {
 public:
  // Opens the source for the application's views; throws core::InputError. An empty URI:
  // no tracker, the fovea rests at the view centre (logged as a warning).
  LayerGaze(const std::string& uri, const core::DisplayPreset& display);
  // The fovea for the frame displayed at `display_time_ns` (XrTime: CLOCK_MONOTONIC), from
  // the action when given, else from the source (recordings start at the first frame).
  devices::FoveaGaze frame(std::int64_t display_time_ns, const ActionGaze* action);
  std::string describe() const { return gaze_.describe(); }
  bool live() const { return gaze_.live(); }  // the source's times are the host's clock

 private:
  devices::FoveationGaze gaze_;
};

}  // namespace fovea::layer
