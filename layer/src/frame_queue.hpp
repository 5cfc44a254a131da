#pragma once
// The frames a session has in flight, keyed by the display time xrWaitFrame predicted for
// them: a pipelined application waits for frame N+1 (on one thread) before it ends frame N
// (on another), so one "current frame" record would mix two frames. xrBeginFrame begins the
// oldest waited frame, xrEndFrame ends the frame whose predicted display time it submits
// (else the oldest begun one), as the OpenXR frame loop pairs them.
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>

#include "frame_log.hpp"

namespace fovea::layer {

class FrameQueue {
 public:
  // At most this many frames waited and not ended: older ones are dropped (an application
  // that waits without ending them).
  static constexpr std::size_t kMaxInFlight = 8;

  // xrWaitFrame returned a frame to display at `display_time_ns`.
  void waited(std::int64_t display_time_ns, std::int64_t call_ns, std::int64_t return_ns);
  // xrBeginFrame succeeded: the oldest waited frame not begun yet begins.
  void begun(std::int64_t begin_ns);
  // xrEndFrame for `display_time_ns`: the record of that frame (else of the oldest begun one),
  // taken out of the queue; nothing when no frame was begun (the call is the application's error).
  std::optional<FrameTimes> end(std::int64_t display_time_ns);
  std::size_t in_flight() const { return frames_.size(); }

 private:
  std::map<std::int64_t, FrameTimes> frames_;  // by predicted display time
  std::int64_t next_frame_ = 0;
};

}  // namespace fovea::layer
