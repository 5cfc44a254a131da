#pragma once
// Composable filter stages on any sample stream, and short-horizon prediction.
//  - "ivt":     I-VT classification (30 °/s; sets GazeSample::motion) with gap fill: runs of
//               lost samples shorter than 75 ms are filled by interpolation (Olsen 2012).
//  - "oneeuro": One Euro filter (Casiez, Roussel & Vogel, CHI 2012) per eye and axis on the
//               gaze angles, reset after dropouts.
// Prediction (GazePredictor) extrapolates to the display time at constant velocity during
// fixation and pursuit, and never across a saccade onset (hold, or the landing estimate
// from the main sequence once the peak velocity has passed); PredictMode::Landing fits the
// saccade in flight instead (saccade_predict.hpp). What the fovea does while the
// eye is not tracked is the foveation gaze's policy (foveation_gaze.hpp), not a filter.
#include <deque>
#include <memory>
#include <string_view>

#include "fovea/devices/gaze.hpp"
#include "fovea/devices/ivt.hpp"
#include "fovea/devices/saccade_predict.hpp"

namespace fovea::devices {

struct OneEuroParams {
  double min_cutoff_hz = 1.0;   // jitter at rest
  double beta = 0.05;           // per °/s: lag at speed
  double d_cutoff_hz = 1.0;     // derivative smoothing
  core::TimeNs reset_gap_ns = 100'000'000;
};

// The scalar filter (paper: Eq. for α = 1/(1 + τ/Te), τ = 1/(2π·fc); fc = mincutoff + β·|dx̂|).
class OneEuro {
 public:
  explicit OneEuro(const OneEuroParams& p = {}) : p_(p) {}
  double filter(double x, double dt_s);
  void reset() { init_ = false; }

 private:
  OneEuroParams p_;
  bool init_ = false;
  double x_ = 0, dx_ = 0;
};

struct FilterParams {
  IvtParams ivt;
  OneEuroParams one_euro;
};

// Wraps `inner` with the comma-separated stages of `spec` ("" = none). Throws InputError.
std::unique_ptr<SampleStream> apply_filters(std::unique_ptr<SampleStream> inner, std::string_view spec, const FilterParams& p);

struct PredictParams {
  PredictMode mode = PredictMode::Linear;         // None predicts nothing
  LandingParams landing;                          // PredictMode::Landing
  double saccade_deg_s = 30;                      // above: a saccade, no extrapolation
  core::TimeNs velocity_window_ns = 30'000'000;   // velocity from the samples of the last 30 ms
};

class GazePredictor {
 public:
  explicit GazePredictor(const PredictParams& p = {}) : p_(p) {}
  // The gaze at t ≥ newest sample time, at most `horizon_ns` ahead of it (Landing: a trusted
  // fit of the saccade in flight gives its position at t, uncapped); `history` holds the
  // recent samples in time order, of which the first `count` are used (the newest last).
  // Only the directions move: the times stay those of the newest sample (it was measured
  // then; the prediction is not a measurement).
  GazeSample predict(const std::deque<GazeSample>& history, std::size_t count, core::TimeNs t,
                     core::TimeNs horizon_ns) const;
  GazeSample predict(const std::deque<GazeSample>& history, core::TimeNs t, core::TimeNs horizon_ns) const {
    return predict(history, history.size(), t, horizon_ns);
  }

 private:
  PredictParams p_;
};

}  // namespace fovea::devices
