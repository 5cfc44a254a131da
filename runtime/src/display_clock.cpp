#include "display_clock.hpp"

#include <algorithm>
#include <cmath>

namespace fovea::runtime {

DisplayClock::DisplayClock(double refresh_hz)
    : period_(static_cast<core::TimeNs>(std::llround(1e9 / refresh_hz))),
      // Compositor budget: 20 % of the frame, at least 3 ms (a common open-loop pacing choice).
      budget_(std::max<core::TimeNs>(period_ / 5, core::ms_to_ns(3.0))) {}

FrameSlot DisplayClock::next(core::TimeNs now) {
  if (!started_) {
    t0_ = now + period_ + budget_;
    started_ = true;
  }
  FrameSlot s;
  s.index = next_index_++;
  s.display_ns = t0_ + s.index * period_;
  s.wake_ns = s.display_ns - period_ - budget_;
  return s;
}

}  // namespace fovea::runtime
