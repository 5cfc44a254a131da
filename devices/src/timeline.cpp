#include "fovea/devices/timeline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fovea::devices {

TimelineSource::TimelineSource(std::unique_ptr<SampleStream> stream, const SourceOptions& opt)
    : stream_(std::move(stream)), opt_(opt), opened_ns_(core::now_ns()) {}

void TimelineSource::restart() {
  stream_->rewind();
  win_.clear();
  ended_ = trimmed_ = false;
}

void TimelineSource::pull_until(core::TimeNs t) {
  GazeSample s;
  while ((win_.empty() || win_.back().t_ns < t || stream_->live()) && !ended_) {
    if (!stream_->next(s)) {
      ended_ = !stream_->live();
      break;
    }
    win_.push_back(s);
    // Keep window_ns of history, and always the two samples around the newest time.
    while (win_.size() > 2 && win_.back().t_ns - win_[1].t_ns > opt_.window_ns) {
      win_.pop_front();
      trimmed_ = true;
    }
  }
}

GazeSample TimelineSource::at_recording_time(core::TimeNs tt) {
  if (!stream_->live()) {
    if (!win_.empty() && tt < win_.front().t_ns && trimmed_) restart();
    pull_until(tt);
    if (opt_.loop && ended_ && !win_.empty() && tt > win_.back().t_ns) {
      if (period_ < 0) {  // one nominal sample period after the last sample
        const core::TimeNs dt = win_.size() > 1 ? win_.back().t_ns - win_[win_.size() - 2].t_ns : 0;
        // Saturating: a recording spanning ~int64 ns must not wrap to a negative period.
        if (__builtin_add_overflow(win_.back().t_ns, std::max<core::TimeNs>(dt, 1), &period_))
          period_ = std::numeric_limits<core::TimeNs>::max();
      }
      tt %= period_;
      if (win_.empty() || tt < win_.front().t_ns) restart();
      pull_until(tt);
    }
  } else {
    pull_until(tt);
  }
  if (win_.empty()) {  // nothing yet: a lost sample looking ahead
    GazeSample s;
    s.t_ns = tt;
    return s;
  }
  if (tt <= win_.front().t_ns) return win_.front();
  if (tt >= win_.back().t_ns) {
    // Live: predict to the requested (display) time, at most horizon_ns ahead. Recordings
    // are clamped at their end.
    if (stream_->live() && opt_.horizon_ns > 0) return predictor_.predict(win_, tt, opt_.horizon_ns);
    return win_.back();
  }
  const auto it = std::upper_bound(win_.begin(), win_.end(), tt,
                                   [](core::TimeNs t, const GazeSample& s) { return t < s.t_ns; });
  const GazeSample& b = *it;
  const GazeSample& a = *(it - 1);
  if (b.t_ns - a.t_ns > opt_.max_gap_ns) {  // no interpolation across a gap: lost
    GazeSample s = (tt - a.t_ns < b.t_ns - tt) ? a : b;
    s.combined.flags = s.left.flags = s.right.flags = kLost;
    s.combined.confidence = s.left.confidence = s.right.confidence = 0;
    return s;
  }
  return interpolate(a, b, tt);
}

GazeSample TimelineSource::sample_at(core::TimeNs t) {
  std::lock_guard lock(mutex_);
  const core::TimeNs tt =
      stream_->live() ? t : std::llround(std::clamp(static_cast<double>(t) * opt_.speed, -9.2e18, 9.2e18));
  GazeSample s = at_recording_time(tt);
  s.t_ns = t;
  return s;
}

GazeSample TimelineSource::latest() {
  if (stream_->live()) {
    std::lock_guard lock(mutex_);
    pull_until(0);
    if (win_.empty()) return GazeSample{};
    return win_.back();
  }
  return sample_at(core::now_ns() - opened_ns_);
}

}  // namespace fovea::devices
