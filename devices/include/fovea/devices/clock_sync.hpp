#pragma once
// Device -> host clock mapping for live trackers. Every report gives a pair (device time,
// host receive time); receive = device·(1 + drift) + offset + transport delay, delay ≥ 0.
// The lower envelope of (host − device) is the delay-free offset: per time bucket keep the
// minimum, then fit a line (offset and drift) through the recent bucket minima by least
// squares. The constant minimum transport delay is not observable and stays in the offset.
#include <deque>

#include "fovea/core/clock.hpp"

namespace fovea::devices {

class ClockSync {
 public:
  explicit ClockSync(core::TimeNs bucket_ns = 250'000'000, int max_buckets = 40)
      : bucket_ns_(bucket_ns), max_buckets_(max_buckets) {}
  void add(core::TimeNs device_ns, core::TimeNs host_ns);
  // Host-clock time of a device time stamp (device + estimated offset incl. drift).
  core::TimeNs to_host(core::TimeNs device_ns) const;
  double drift_ppm() const { return slope_ * 1e6; }
  bool ready() const { return !buckets_.empty(); }
  void reset() { *this = ClockSync(bucket_ns_, max_buckets_); }

 private:
  void refit();
  struct Bucket {
    core::TimeNs device = 0;  // device time of the minimum
    double diff = 0;          // host − device at the minimum, relative to ref_diff_
  };
  core::TimeNs bucket_ns_;
  int max_buckets_;
  std::deque<Bucket> buckets_;
  core::TimeNs bucket_start_ = 0, ref_device_ = 0, ref_diff_ = 0;
  bool have_ref_ = false;
  double intercept_ = 0, slope_ = 0;  // diff(device) = intercept + slope·(device − ref_device)
};

}  // namespace fovea::devices
