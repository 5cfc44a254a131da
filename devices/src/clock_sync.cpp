#include "fovea/devices/clock_sync.hpp"

#include <cmath>

namespace fovea::devices {

void ClockSync::add(core::TimeNs device, core::TimeNs host) {
  if (!have_ref_) {
    have_ref_ = true;
    ref_device_ = device;
    ref_diff_ = host - device;
    bucket_start_ = device;
  }
  const double diff = static_cast<double>((host - device) - ref_diff_);
  if (buckets_.empty() || device - bucket_start_ >= bucket_ns_ || device < bucket_start_) {
    buckets_.push_back({device, diff});
    bucket_start_ = device;
    while (static_cast<int>(buckets_.size()) > max_buckets_) buckets_.pop_front();
  } else if (diff < buckets_.back().diff) {
    buckets_.back() = {device, diff};
  }
  refit();
}

void ClockSync::refit() {
  const std::size_t n = buckets_.size();
  // The newest bucket is still filling: its minimum is not settled yet, use it only alone.
  const std::size_t m = n > 2 ? n - 1 : n;
  if (m < 3) {
    double lo = buckets_.front().diff;
    for (const Bucket& b : buckets_) lo = std::min(lo, b.diff);
    intercept_ = lo;
    slope_ = 0;
    return;
  }
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const double x = static_cast<double>(buckets_[i].device - ref_device_), y = buckets_[i].diff;
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double den = m * sxx - sx * sx;
  slope_ = den > 0 ? (m * sxy - sx * sy) / den : 0;
  intercept_ = (sy - slope_ * sx) / m;
  // A line through minima can still sit above a newer, lower point: never map later than seen.
  const Bucket& last = buckets_.back();
  const double at_last = intercept_ + slope_ * static_cast<double>(last.device - ref_device_);
  if (last.diff < at_last) intercept_ -= at_last - last.diff;
}

core::TimeNs ClockSync::to_host(core::TimeNs device) const {
  if (!have_ref_) return device;
  const double d = intercept_ + slope_ * static_cast<double>(device - ref_device_);
  return device + ref_diff_ + std::llround(d);
}

}  // namespace fovea::devices
