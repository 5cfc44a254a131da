#pragma once
// One streaming pass over a gaze recording: counts, rate, validity and eye-movement events
// (the figures behind `fovea gaze info`). Bounded memory.
#include <cstdint>
#include <functional>

#include "fovea/devices/ivt.hpp"

namespace fovea::devices {

struct GazeSummary {
  std::uint64_t samples = 0, tracked = 0;
  double rate_hz = 0;      // from the median sample interval (robust to gaps)
  double duration_s = 0;   // first to last sample
  std::uint64_t fixations = 0, saccades = 0, blinks = 0;
  double valid_fraction() const { return samples ? static_cast<double>(tracked) / samples : 0.0; }
};

struct SummaryParams {
  IvtParams ivt;
  core::TimeNs min_fixation_ns = 60'000'000;  // shorter fixation runs are not counted
  // Formats without blink markers: an untracked run of this length is counted as a blink
  // (the usual 80 ms..500 ms plausibility window); formats with markers count marked runs.
  bool infer_blinks = true;
  core::TimeNs blink_min_ns = 80'000'000, blink_max_ns = 500'000'000;
};

// Event segmentation of a sample stream (I-VT + blink runs), fed one sample at a time.
class EventSegmenter {
 public:
  enum class Kind { Fixation, Saccade, Blink };
  using Callback = std::function<void(Kind, core::TimeNs start, core::TimeNs end)>;
  EventSegmenter(const SummaryParams& p, Callback cb) : p_(p), ivt_(p.ivt), cb_(std::move(cb)) {}
  void add(const GazeSample& s);
  void finish();

 private:
  void close_motion(core::TimeNs end);
  SummaryParams p_;
  IvtClassifier ivt_;
  Callback cb_;
  Motion run_ = Motion::Unknown;
  core::TimeNs run_start_ = 0, last_t_ = 0;
  bool gap_ = false, gap_blink_ = false;
  core::TimeNs gap_start_ = 0;
};

GazeSummary summarize(SampleStream& stream, const SummaryParams& p = {});

}  // namespace fovea::devices
