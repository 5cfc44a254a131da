#pragma once
// One streaming pass over a gaze recording: counts, rate, validity, data quality and
// eye-movement events (the figures behind `fovea gaze info`). Bounded memory.
#include <cstdint>
#include <functional>

#include <glm/vec3.hpp>

#include "fovea/devices/ivt.hpp"

namespace fovea::devices {

// Data quality as eye-tracking papers report it (Holmqvist, Nyström & Mulvey 2012, "Eye
// tracker data quality: what it is and how to measure it", ETRA; the RMS-S2S/STD pair as
// in Niehorster et al. 2020). Precision is measured inside I-VT fixations only, where the
// eye is (nominally) still, and reported as the median over fixations, in degrees.
struct DataQuality {
  // RMS-S2S: sqrt(mean(theta_i^2)), theta_i the angle between successive samples.
  double rms_s2s_deg = 0;
  // STD: sqrt(s_x^2 + s_y^2), s the standard deviations of the horizontal and vertical gaze
  // angles around the fixation's mean.
  double std_deg = 0;
  std::uint64_t fixations_measured = 0;
  // Data loss: the share of samples without a valid gaze; and the same without the samples
  // the format marks as blinks (blinks are no tracker failure).
  double data_loss = 0, data_loss_excluding_blinks = 0;
};

struct GazeSummary {
  std::uint64_t samples = 0, tracked = 0, blink_samples = 0;
  double rate_hz = 0;      // from the median sample interval (robust to gaps)
  double duration_s = 0;   // first to last sample
  std::uint64_t fixations = 0, saccades = 0, blinks = 0;
  DataQuality quality;
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

struct GazeEvent {
  enum class Kind { Fixation, Saccade, Blink };
  Kind kind = Kind::Fixation;
  core::TimeNs start_ns = 0, end_ns = 0;
  // Gaze at the start and the end of the event (blinks: the last gaze before, the first after).
  glm::dvec3 start_dir{0, 0, -1}, end_dir{0, 0, -1};
  double amplitude_deg = 0;   // angle between start_dir and end_dir
  std::uint64_t samples = 0;  // tracked samples inside (blinks: 0)
  double rms_s2s_deg = 0, std_deg = 0;  // fixations: precision (DataQuality)
};
const char* event_kind_name(GazeEvent::Kind k);  // "fixation", "saccade", "blink"

// Event segmentation of a sample stream (I-VT + blink runs), fed one sample at a time.
class EventSegmenter {
 public:
  using Kind = GazeEvent::Kind;
  using Callback = std::function<void(const GazeEvent&)>;
  EventSegmenter(const SummaryParams& p, Callback cb) : p_(p), ivt_(p.ivt), cb_(std::move(cb)) {}
  void add(const GazeSample& s);
  void finish();

 private:
  void close_motion(core::TimeNs end);
  SummaryParams p_;
  IvtClassifier ivt_;
  Callback cb_;
  Motion run_ = Motion::Unknown;
  GazeEvent ev_;  // the motion run being built
  // Fixation precision accumulators: sums of angles, squared angles, squared S2S steps.
  double sx_ = 0, sy_ = 0, sxx_ = 0, syy_ = 0, s2s_ = 0;
  std::uint64_t steps_ = 0;
  core::TimeNs last_t_ = 0, last_seen_ = 0;  // last classified / last sample
  glm::dvec3 last_dir_{0, 0, -1};
  bool have_dir_ = false;
  bool gap_ = false, gap_blink_ = false;
  core::TimeNs gap_start_ = 0;
  glm::dvec3 gap_dir_{0, 0, -1};
};

// `on_event` (optional) receives every event in time order as summarize() finds it.
GazeSummary summarize(SampleStream& stream, const SummaryParams& p = {}, const EventSegmenter::Callback& on_event = {});

}  // namespace fovea::devices
