#include "fovea/devices/ivt.hpp"

namespace fovea::devices {

Motion IvtClassifier::classify(const GazeSample& s) {
  if (!s.tracked()) {
    if (!hist_.empty() && s.t_ns - hist_.back().t_ns > p_.gap_fill_ns) reset();
    v_ = 0;
    return Motion::Unknown;
  }
  if (!hist_.empty() && s.t_ns - hist_.back().t_ns > p_.gap_fill_ns) reset();
  hist_.push_back(s);
  // Keep the newest sample at least velocity_window_ns older than s (or the oldest we have).
  while (hist_.size() > 2 && s.t_ns - hist_[1].t_ns >= p_.velocity_window_ns) hist_.pop_front();
  // Until the history spans the whole window (at the start and after a restart) the
  // velocity would be taken over fewer samples, i.e. over one interval at high rates, where
  // noise alone exceeds the threshold (noise speed ~ sqrt(2)·sigma·rate): no decision yet.
  const GazeSample& a = hist_.front();
  if (hist_.size() < 2 || s.t_ns - a.t_ns < p_.velocity_window_ns) {
    v_ = 0;
    return Motion::Unknown;
  }
  const double dt = static_cast<double>(s.t_ns - a.t_ns) * 1e-9;
  v_ = dt > 0 ? core::angle_deg(a.combined.dir, s.combined.dir) / dt : 0;
  return v_ >= p_.threshold_deg_s ? Motion::Saccade : Motion::Fixation;
}

}  // namespace fovea::devices
