#include "fovea/devices/timeline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fovea::devices {

TimelineSource::TimelineSource(std::unique_ptr<SampleStream> stream, const SourceOptions& opt)
    : stream_(std::move(stream)), opt_(opt), opened_ns_(core::now_ns()), predictor_(PredictParams{.mode = opt.predict}) {}

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

GazeSample TimelineSource::at_recording_time(core::TimeNs tt, core::TimeNs ahead_ns, bool predict) {
  loop_base_ = 0;
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
      loop_base_ = tt - tt % period_;
      tt %= period_;
      if (win_.empty() || tt < win_.front().t_ns) restart();
      pull_until(tt);
    }
  } else {
    pull_until(tt);
  }
  // The newest sample measured at or before tt: a later one is not known yet at tt.
  const auto it = std::upper_bound(win_.begin(), win_.end(), tt,
                                   [](core::TimeNs t, const GazeSample& s) { return t < s.t_ns; });
  if (it == win_.begin()) {  // nothing measured yet
    GazeSample s;
    s.t_ns = kNoSample;
    return s;
  }
  const std::size_t count = static_cast<std::size_t>(it - win_.begin());
  GazeSample s = win_[count - 1];
  // The end of a recording holds its last sample; elsewhere an old newest sample is stale.
  const bool recording_over = ended_ && count == win_.size();
  if (recording_over || (tt == s.t_ns && ahead_ns == 0)) return s;
  if (tt - s.t_ns > opt_.max_gap_ns) {
    s.combined.flags = s.left.flags = s.right.flags = kLost;
    s.combined.confidence = s.left.confidence = s.right.confidence = 0;
    return s;
  }
  // From the samples measured by tt only: win_ may hold later ones (read ahead).
  return predict && opt_.predicts() ? predictor_.predict(win_, count, tt + ahead_ns, opt_.horizon_ns) : s;
}

GazeSample TimelineSource::on_caller_timeline(core::TimeNs t, core::TimeNs ahead_ns, bool predict) {
  std::lock_guard lock(mutex_);
  const bool live = stream_->live();
  const auto scaled = [&](core::TimeNs x) {
    return live ? x : std::llround(std::clamp(static_cast<double>(x) * opt_.speed, -9.2e18, 9.2e18));
  };
  GazeSample s = at_recording_time(scaled(t), scaled(ahead_ns), predict);
  // Back from recording time to the caller's timeline: the sample's own time, not t.
  // A recording carries no receive delay (a captured host clock is not this timeline).
  if (!live && s.t_ns != kNoSample)
    s.t_ns = s.host_time_ns = std::min<core::TimeNs>(t, std::llround(static_cast<double>(s.t_ns + loop_base_) / opt_.speed));
  return s;
}

GazeSample TimelineSource::read_at(core::TimeNs read_ns, core::TimeNs target_ns) {
  const core::TimeNs avail = std::min(read_ns, target_ns);
  return on_caller_timeline(avail, target_ns - avail, true);
}

GazeSample TimelineSource::truth_at(core::TimeNs t) {
  if (stream_->live()) return GazeSource::truth_at(t);
  return on_caller_timeline(t, 0, false);
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
