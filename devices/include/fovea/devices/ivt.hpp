#pragma once
// I-VT: velocity-threshold classification of gaze samples (Salvucci & Goldberg 2000),
// with Tobii's defaults (Olsen 2012): 30 °/s, gaps shorter than 75 ms bridged.
// Causal, one sample at a time; velocity over a short window to tame tracker noise.
#include <deque>

#include "fovea/devices/gaze.hpp"

namespace fovea::devices {

struct IvtParams {
  double threshold_deg_s = 30;
  core::TimeNs gap_fill_ns = 75'000'000;   // longer gaps restart the classifier
  core::TimeNs velocity_window_ns = 20'000'000;  // velocity over (at least) this span
};

class IvtClassifier {
 public:
  explicit IvtClassifier(const IvtParams& p = {}) : p_(p) {}
  // Classifies `s` (the combined gaze). Untracked samples are Unknown; they do not reset
  // the history unless the gap exceeds gap_fill_ns. Tracked samples are Unknown too until
  // the history spans velocity_window_ns (at the start and after such a reset).
  Motion classify(const GazeSample& s);
  // Angular speed (°/s) behind the last classification; 0 if unknown.
  double velocity_deg_s() const { return v_; }
  // The gaze at the start of the window behind the last classification (where a saccade
  // detected now started from: the window lags the eye by up to velocity_window_ns).
  glm::dvec3 window_start_dir() const { return hist_.empty() ? glm::dvec3(0, 0, -1) : hist_.front().combined.dir; }
  void reset() { hist_.clear(); v_ = 0; }

 private:
  IvtParams p_;
  std::deque<GazeSample> hist_;  // tracked samples within the velocity window
  double v_ = 0;
};

}  // namespace fovea::devices
