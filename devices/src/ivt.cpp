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
  if (hist_.size() < 2) {
    v_ = 0;
    return Motion::Unknown;
  }
  const GazeSample& a = hist_.front();
  const double dt = static_cast<double>(s.t_ns - a.t_ns) * 1e-9;
  v_ = dt > 0 ? core::angle_deg(a.combined.dir, s.combined.dir) / dt : 0;
  return v_ >= p_.threshold_deg_s ? Motion::Saccade : Motion::Fixation;
}

}  // namespace fovea::devices
