#include "fovea/devices/analysis.hpp"

#include <algorithm>
#include <vector>

namespace fovea::devices {

void EventSegmenter::close_motion(core::TimeNs end) {
  if (run_ == Motion::Saccade) cb_(Kind::Saccade, run_start_, end);
  if (run_ == Motion::Fixation && end - run_start_ >= p_.min_fixation_ns) cb_(Kind::Fixation, run_start_, end);
  run_ = Motion::Unknown;
}

void EventSegmenter::add(const GazeSample& s) {
  if (!s.tracked()) {
    if (!gap_) {
      gap_ = true;
      gap_blink_ = false;
      gap_start_ = s.t_ns;
    }
    gap_blink_ = gap_blink_ || (s.combined.flags & kBlink);
  } else if (gap_) {
    gap_ = false;
    const core::TimeNs d = s.t_ns - gap_start_;
    if (gap_blink_ || (p_.infer_blinks && d >= p_.blink_min_ns && d <= p_.blink_max_ns)) cb_(Kind::Blink, gap_start_, s.t_ns);
  }
  const Motion m = ivt_.classify(s);
  if (m == Motion::Unknown) {
    // Short gaps are bridged: the run continues unless the classifier restarted.
    if (s.tracked() || s.t_ns - last_t_ > p_.ivt.gap_fill_ns) close_motion(last_t_);
  } else {
    if (m != run_) {
      close_motion(s.t_ns);
      run_ = m;
      run_start_ = s.t_ns;
    }
    last_t_ = s.t_ns;
  }
}

void EventSegmenter::finish() {
  close_motion(last_t_);
  if (gap_ && gap_blink_) cb_(Kind::Blink, gap_start_, last_t_);
  gap_ = false;
}

GazeSummary summarize(SampleStream& stream, const SummaryParams& p) {
  GazeSummary out;
  EventSegmenter seg(p, [&](EventSegmenter::Kind k, core::TimeNs, core::TimeNs) {
    (k == EventSegmenter::Kind::Fixation ? out.fixations : k == EventSegmenter::Kind::Saccade ? out.saccades : out.blinks)++;
  });
  std::vector<core::TimeNs> dts;  // the first intervals: enough for a robust median
  constexpr std::size_t kMaxIntervals = 100000;
  GazeSample s;
  core::TimeNs first = 0, last = 0;
  while (stream.next(s)) {
    if (out.samples == 0) first = s.t_ns;
    else if (dts.size() < kMaxIntervals) dts.push_back(s.t_ns - last);
    last = s.t_ns;
    ++out.samples;
    if (s.tracked()) ++out.tracked;
    seg.add(s);
  }
  seg.finish();
  out.duration_s = static_cast<double>(last - first) * 1e-9;
  if (!dts.empty()) {
    std::nth_element(dts.begin(), dts.begin() + dts.size() / 2, dts.end());
    const core::TimeNs med = dts[dts.size() / 2];
    out.rate_hz = med > 0 ? 1e9 / static_cast<double>(med) : 0;
  }
  return out;
}

}  // namespace fovea::devices
