#include "fovea/devices/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace fovea::devices {

namespace {
// Horizontal and vertical gaze angles (degrees): the coordinates STD is taken in.
glm::dvec2 angles_deg(const glm::dvec3& d) {
  return glm::dvec2(std::atan2(d.x, -d.z), std::atan2(d.y, std::hypot(d.x, d.z))) * (180.0 / std::numbers::pi);
}
}  // namespace

const char* event_kind_name(GazeEvent::Kind k) {
  switch (k) {
    case GazeEvent::Kind::Fixation: return "fixation";
    case GazeEvent::Kind::Saccade: return "saccade";
    case GazeEvent::Kind::Blink: return "blink";
  }
  return "?";
}

void EventSegmenter::close_motion(core::TimeNs end) {
  ev_.end_ns = end;
  ev_.amplitude_deg = core::angle_deg(ev_.start_dir, ev_.end_dir);
  if (run_ == Motion::Fixation && ev_.samples > 1) {
    const double n = static_cast<double>(ev_.samples);
    const double vx = std::max(0.0, sxx_ / n - (sx_ / n) * (sx_ / n)), vy = std::max(0.0, syy_ / n - (sy_ / n) * (sy_ / n));
    ev_.std_deg = std::sqrt(vx + vy);
    ev_.rms_s2s_deg = steps_ ? std::sqrt(s2s_ / static_cast<double>(steps_)) : 0;
  }
  if (run_ == Motion::Saccade || (run_ == Motion::Fixation && end - ev_.start_ns >= p_.min_fixation_ns)) cb_(ev_);
  run_ = Motion::Unknown;
}

void EventSegmenter::add(const GazeSample& s) {
  last_seen_ = s.t_ns;
  if (!s.tracked()) {
    if (!gap_) {
      gap_ = true;
      gap_blink_ = false;
      gap_start_ = s.t_ns;
      gap_dir_ = last_dir_;
    }
    gap_blink_ = gap_blink_ || (s.combined.flags & kBlink);
  } else if (gap_) {
    gap_ = false;
    const core::TimeNs d = s.t_ns - gap_start_;
    if (gap_blink_ || (p_.infer_blinks && d >= p_.blink_min_ns && d <= p_.blink_max_ns)) {
      GazeEvent b;
      b.kind = Kind::Blink;
      b.start_ns = gap_start_;
      b.end_ns = s.t_ns;
      b.start_dir = gap_dir_;
      b.end_dir = s.combined.dir;
      b.amplitude_deg = core::angle_deg(b.start_dir, b.end_dir);
      cb_(b);
    }
  }
  const Motion m = ivt_.classify(s);
  if (m == Motion::Unknown) {
    // Short gaps are bridged: the run continues unless the classifier restarted.
    if (s.tracked() || s.t_ns - last_t_ > p_.ivt.gap_fill_ns) close_motion(last_t_);
  } else {
    if (m != run_) {
      close_motion(s.t_ns);
      run_ = m;
      ev_ = GazeEvent{};
      ev_.kind = m == Motion::Saccade ? Kind::Saccade : Kind::Fixation;
      ev_.start_ns = s.t_ns;
      // A saccade starts where the gaze was at the start of the velocity window that
      // crossed the threshold (the eye may have moved a while before the window's speed did).
      ev_.start_dir = m == Motion::Saccade ? ivt_.window_start_dir() : s.combined.dir;
      sx_ = sy_ = sxx_ = syy_ = s2s_ = 0;
      steps_ = 0;
    } else if (m == Motion::Fixation && have_dir_) {
      const double step = core::angle_deg(last_dir_, s.combined.dir);
      s2s_ += step * step;
      ++steps_;
    }
    ev_.end_dir = s.combined.dir;
    ++ev_.samples;
    if (m == Motion::Fixation) {
      const glm::dvec2 a = angles_deg(s.combined.dir);
      sx_ += a.x;
      sy_ += a.y;
      sxx_ += a.x * a.x;
      syy_ += a.y * a.y;
    }
    last_t_ = s.t_ns;
  }
  if (s.tracked()) {
    last_dir_ = s.combined.dir;
    have_dir_ = true;
  }
}

void EventSegmenter::finish() {
  close_motion(last_t_);
  if (gap_ && gap_blink_) {
    GazeEvent b;
    b.kind = Kind::Blink;
    b.start_ns = gap_start_;
    b.end_ns = last_seen_;  // the recording ends inside the blink
    b.start_dir = b.end_dir = gap_dir_;
    cb_(b);
  }
  gap_ = false;
}

GazeSummary summarize(SampleStream& stream, const SummaryParams& p, const EventSegmenter::Callback& on_event) {
  GazeSummary out;
  std::vector<double> s2s, stds;  // per fixation: a few per second of recording
  constexpr std::size_t kMaxFixations = 1'000'000;
  EventSegmenter seg(p, [&](const GazeEvent& e) {
    switch (e.kind) {
      case GazeEvent::Kind::Fixation:
        ++out.fixations;
        if (e.samples > 2 && s2s.size() < kMaxFixations) {
          s2s.push_back(e.rms_s2s_deg);
          stds.push_back(e.std_deg);
        }
        break;
      case GazeEvent::Kind::Saccade: ++out.saccades; break;
      case GazeEvent::Kind::Blink: ++out.blinks; break;
    }
    if (on_event) on_event(e);
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
    else if (s.combined.flags & kBlink) ++out.blink_samples;
    seg.add(s);
  }
  seg.finish();
  out.duration_s = static_cast<double>(last - first) * 1e-9;
  auto median = [](std::vector<double>& v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  if (!dts.empty()) {
    std::nth_element(dts.begin(), dts.begin() + static_cast<std::ptrdiff_t>(dts.size() / 2), dts.end());
    const core::TimeNs med = dts[dts.size() / 2];
    out.rate_hz = med > 0 ? 1e9 / static_cast<double>(med) : 0;
  }
  DataQuality& q = out.quality;
  q.fixations_measured = s2s.size();
  q.rms_s2s_deg = median(s2s);
  q.std_deg = median(stds);
  if (out.samples) {
    const double n = static_cast<double>(out.samples);
    q.data_loss = static_cast<double>(out.samples - out.tracked) / n;
    const double non_blink = n - static_cast<double>(out.blink_samples);
    q.data_loss_excluding_blinks =
        non_blink > 0 ? static_cast<double>(out.samples - out.tracked - out.blink_samples) / non_blink : 0;
  }
  return out;
}

}  // namespace fovea::devices
