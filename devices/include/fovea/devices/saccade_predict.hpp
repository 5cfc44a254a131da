#pragma once
// Saccade landing-position prediction in the manner of Arabadzhiyska et al. 2017 ("Saccade
// Landing Position Prediction for Gaze-Contingent Rendering", ACM TOG 36(4)): once a saccade
// is detected, the samples seen so far are fitted with a displacement profile whose duration
// and peak velocity follow the main sequence of its amplitude; the fitted amplitude, laid
// along the saccade's direction from its onset, is where the eye lands. The foveation can
// render for that point while saccadic suppression hides the mismatch in flight.
// Also: a causal saccade-onset detector (the marker mode's trigger, docs/marker.md).
#include <cstddef>
#include <deque>

#include <glm/vec3.hpp>

#include "fovea/devices/gaze.hpp"

namespace fovea::devices {

struct LandingParams {
  // Sample-to-sample speed that marks a sample as inside a saccade. Above the speed that a
  // 0.25° RMS tracker noise reaches at 120 Hz (≈ 60 °/s), below the peak of a 2° saccade.
  double onset_deg_s = 75;
  // A saccade counts once its newest sample is this far from where it started: noise alone
  // (two samples of 0.25° RMS) gets there with probability ≈ 1e-4 per sample.
  double min_progress_deg = 1.5;
  std::size_t min_samples = 2;             // samples inside the saccade before a fit is trusted
  core::TimeNs max_gap_ns = 40'000'000;    // a dropout mid-saccade up to this is bridged
  core::TimeNs speed_span_ns = 5'000'000;  // speeds over at least this span (noise at high rates)
  double max_amplitude_deg = 80;
  // The fraction of the duration at which half the amplitude is covered: below a half, as
  // saccades accelerate faster than they brake (Van Opstal & Van Gisbergen 1987). 0.4 puts
  // the fitted profile's peak velocity at about a third of the duration, as in the synthetic
  // eye's profile; a per-user calibration (as in Arabadzhiyska et al.) would set it.
  double half_way_fraction = 0.4;
  // A fit whose RMS residual exceeds this fraction of its amplitude (or 0.5°) is not trusted.
  double max_rms_fraction = 0.25;
  // The fixation before the onset, whose samples give the onset direction and the noise.
  core::TimeNs fixation_ns = 50'000'000;
};

struct LandingEstimate {
  bool in_saccade = false;  // the newest samples are a saccade in flight
  bool confident = false;   // the fit is trusted (else: use the newest sample)
  core::TimeNs onset_ns = 0, duration_ns = 0;  // fitted start and main-sequence duration
  double amplitude_deg = 0;   // fitted
  double progress_deg = 0;    // covered by the newest sample
  glm::dvec3 onset_dir{0, 0, -1}, landing_dir{0, 0, -1};
  glm::dvec3 toward{0, 0, -1};  // unit, orthogonal to onset_dir: the saccade's direction
  double blend = 1, skew = 1;   // the profile behind the fit (saccade_predict.cpp)
  // The fitted gaze at time t: onset_dir before the onset, landing_dir after the end.
  glm::dvec3 at(core::TimeNs t) const;
};

// From the first `count` samples of `history` (time order, the newest last; combined gaze).
// Never throws; non-finite or untracked samples are skipped (a gap above max_gap_ns ends the
// search for the onset); every output is finite.
LandingEstimate estimate_landing(const std::deque<GazeSample>& history, std::size_t count, const LandingParams& p = {});

// Causal onset detector: add() samples in time order; true on the sample at which a
// saccade is first recognised (speed ≥ onset_deg_s and ≥ min_progress_deg from the last
// slow sample). Re-armed by the next slow sample.
class SaccadeOnsetDetector {
 public:
  explicit SaccadeOnsetDetector(const LandingParams& p = {}) : p_(p) {}
  bool add(const GazeSample& s);
  // From the onset until the next slow interval (the saccade's end, where the eye landed).
  bool in_saccade() const { return fired_; }
  void reset() { have_ = fired_ = false; }

 private:
  LandingParams p_;
  bool have_ = false, fired_ = false;
  core::TimeNs last_t_ = 0;
  glm::dvec3 last_{0, 0, -1}, anchor_{0, 0, -1};
};

}  // namespace fovea::devices
