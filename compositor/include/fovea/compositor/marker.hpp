#pragma once
// Marker mode, for measuring end-to-end latency on a real headset with a photodiode or a
// high-speed camera (Saunders & Woods 2014): on an event (a detected saccade onset, or a
// fixed period) the display stage turns a square in a panel corner from black to white for
// a few frames, and logs the event's gaze sample time with the frame's display time.
// docs/marker.md. Environment: FOVEA_MARKER, FOVEA_MARKER_CORNER, FOVEA_MARKER_SIZE,
// FOVEA_MARKER_FRAMES.
#include <cstdint>
#include <optional>

#include "fovea/core/clock.hpp"
#include "fovea/core/image.hpp"

namespace fovea::compositor {

enum class MarkerMode { Off, Saccade, Periodic };
enum class MarkerCorner { TopLeft, TopRight, BottomLeft, BottomRight };

struct MarkerConfig {
  MarkerMode mode = MarkerMode::Off;
  MarkerCorner corner = MarkerCorner::BottomLeft;
  int size_px = 32;       // the square's side on the panel
  int frames = 4;         // lit for this many frames per event (Periodic: then dark as long)
};

// Reads the four variables through `get` (e.g. std::getenv; nullptr or "" = default):
// FOVEA_MARKER off|saccade|periodic, FOVEA_MARKER_CORNER tl|tr|bl|br, FOVEA_MARKER_SIZE
// 1..4096 px, FOVEA_MARKER_FRAMES 1..1000. Throws core::InputError naming the variable.
MarkerConfig marker_config(const char* (*get)(const char*));

// Paints the marker square (clipped to the panel): white when `lit`, else black, so the
// sensor sees the same contrast whatever the scene. Opaque (alpha 1), linear light.
void draw_marker(core::Image& panel, MarkerCorner corner, int size_px, bool lit);

// Which frames are lit: an event (trigger()) lights the next `frames` frames; an event
// while lit is ignored (the sensor must see a dark-to-white edge per logged event).
class MarkerSchedule {
 public:
  explicit MarkerSchedule(const MarkerConfig& c) : c_(c) {}
  // A saccade onset whose newest gaze sample was measured at sample_ns.
  void trigger(core::TimeNs sample_ns);
  struct Frame {
    bool lit = false;
    // Set on the first lit frame of an event: its gaze sample time (Periodic: none).
    std::optional<core::TimeNs> event_sample_ns;
    bool first = false;
  };
  // Advances by one displayed frame.
  Frame next_frame();

 private:
  MarkerConfig c_;
  std::int64_t frame_ = 0, lit_left_ = 0;
  std::optional<core::TimeNs> pending_;
  bool pending_event_ = false;
};

}  // namespace fovea::compositor
