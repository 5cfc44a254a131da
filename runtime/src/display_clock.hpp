#pragma once
// The simulated panel's clock: vsyncs every 1/refresh seconds, in int64 ns of CLOCK_MONOTONIC.
// Lockstep: frame n is always shown at t0 + n·period. A late application is not made to skip
// vsyncs; its lateness (wait return time past the frame's wake time) is reported instead.
// This keeps everything that depends on the display time (head pose, gaze, hence the
// application's content) a function of the frame index, so runs are reproducible.
#include <cstdint>

#include "fovea/core/clock.hpp"

namespace fovea::runtime {

struct FrameSlot {
  std::int64_t index = 0;
  core::TimeNs display_ns = 0;  // predicted display time (middle of the frame's scan-out)
  core::TimeNs wake_ns = 0;     // when xrWaitFrame returns: one period plus the compositor budget earlier
};

class DisplayClock {
 public:
  explicit DisplayClock(double refresh_hz);
  core::TimeNs period() const { return period_; }
  core::TimeNs compositor_budget() const { return budget_; }
  // The next frame's slot; `now` is the time of the xrWaitFrame call. The first call fixes t0
  // so that the first frame's wake time is `now`.
  FrameSlot next(core::TimeNs now);
  core::TimeNs epoch() const { return t0_; }
  bool started() const { return started_; }

 private:
  core::TimeNs period_;
  core::TimeNs budget_;
  core::TimeNs t0_ = 0;
  std::int64_t next_index_ = 0;
  bool started_ = false;
};

}  // namespace fovea::runtime
