#pragma once
// The simulated panel's clock: vsyncs every 1/refresh seconds, in int64 ns of CLOCK_MONOTONIC.
//
// Realtime pacing (the default): each frame is given the next vsync the application can
// still make. A frame whose nominal vsync's wake time has already passed when xrWaitFrame
// is called (the previous frame was slow) moves to the first later vsync whose wake time is
// not past, so the predicted display time is never in the past and xrWaitFrame throttles
// again from there. Lockstep pacing: frame n is always shown at t0 + n·period and a late
// application is never made to skip vsyncs; head pose, gaze and hence the application's
// content are then a function of the frame index, so runs are reproducible (tests comparing
// two runs use it), at the cost of stale predictions for a slow application.
#include <cstdint>

#include "fovea/core/clock.hpp"

namespace fovea::runtime {

enum class Pacing { Realtime, Lockstep };

struct FrameSlot {
  std::int64_t index = 0;       // frame number (0, 1, 2, … in xrWaitFrame order)
  std::int64_t vsync = 0;       // vsync number of the predicted display time
  std::int64_t missed = 0;      // vsyncs skipped because the application was late
  core::TimeNs display_ns = 0;  // predicted display time (middle of the frame's scan-out)
  core::TimeNs wake_ns = 0;     // when xrWaitFrame returns: one period plus the compositor budget earlier
};

class DisplayClock {
 public:
  explicit DisplayClock(double refresh_hz, Pacing pacing = Pacing::Realtime);
  core::TimeNs period() const { return period_; }
  core::TimeNs compositor_budget() const { return budget_; }
  Pacing pacing() const { return pacing_; }
  // The next frame's slot; `now` is the time of the xrWaitFrame call. The first call fixes t0
  // so that the first frame's wake time is `now`. Realtime: wake_ns >= now, hence
  // display_ns > now.
  FrameSlot next(core::TimeNs now);
  // When a frame predicted for `display_ns` and submitted (xrEndFrame) at `submitted_ns` is
  // shown: its vsync if the compositor budget is left before it, else the first later vsync
  // that leaves it. Never earlier than the submission.
  core::TimeNs displayed(core::TimeNs display_ns, core::TimeNs submitted_ns) const;
  // Realtime: for the slot just returned by next(), when xrWaitFrame wakes at `now` so late
  // (a loaded host) that less than the compositor budget is left before its vsync, moves it
  // to the first vsync that leaves it, so the prediction is still ahead when the call returns.
  void reslot(FrameSlot& s, core::TimeNs now);
  core::TimeNs epoch() const { return t0_; }
  bool started() const { return started_; }

 private:
  core::TimeNs vsync_time(std::int64_t k) const { return t0_ + k * period_; }

  core::TimeNs period_;
  core::TimeNs budget_;
  Pacing pacing_;
  core::TimeNs t0_ = 0;
  std::int64_t next_index_ = 0;
  std::int64_t next_vsync_ = 0;
  bool started_ = false;
};

}  // namespace fovea::runtime
