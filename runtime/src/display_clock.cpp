#include "display_clock.hpp"

#include <algorithm>
#include <cmath>

namespace fovea::runtime {

DisplayClock::DisplayClock(double refresh_hz, Pacing pacing)
    : period_(static_cast<core::TimeNs>(std::llround(1e9 / refresh_hz))),
      // Compositor budget: 20 % of the frame, at least 3 ms (a common open-loop pacing choice).
      budget_(std::max<core::TimeNs>(period_ / 5, core::ms_to_ns(3.0))),
      pacing_(pacing) {}

FrameSlot DisplayClock::next(core::TimeNs now) {
  if (!started_) {
    t0_ = now + period_ + budget_;
    started_ = true;
  }
  const core::TimeNs lead = period_ + budget_;  // wake time before the vsync
  std::int64_t k = next_vsync_;
  if (pacing_ == Pacing::Realtime && vsync_time(k) - lead < now) {
    // Late: the first vsync whose wake time is not yet past (ceiling division, now > wake(k)).
    const core::TimeNs since = now - (t0_ - lead);
    k = (since + period_ - 1) / period_;
  }
  FrameSlot s;
  s.index = next_index_++;
  s.vsync = k;
  s.missed = k - next_vsync_;
  s.display_ns = vsync_time(k);
  s.wake_ns = s.display_ns - lead;
  next_vsync_ = k + 1;
  return s;
}

void DisplayClock::reslot(FrameSlot& s, core::TimeNs now) {
  if (pacing_ != Pacing::Realtime) return;
  const std::int64_t skip = (displayed(s.display_ns, now) - s.display_ns) / period_;
  s.vsync += skip;
  s.missed += skip;
  s.display_ns += skip * period_;
  s.wake_ns += skip * period_;
  next_vsync_ = s.vsync + 1;
}

core::TimeNs DisplayClock::displayed(core::TimeNs display_ns, core::TimeNs submitted_ns) const {
  const core::TimeNs ready = submitted_ns + budget_;  // the compositor's share of the frame
  if (ready <= display_ns) return display_ns;
  const core::TimeNs periods = (ready - display_ns + period_ - 1) / period_;
  return display_ns + periods * period_;
}

}  // namespace fovea::runtime
