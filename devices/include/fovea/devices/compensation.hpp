#pragma once
// Latency compensation, measured: the foveal error at display time (angle between the true
// gaze when the frame is shown and the gaze the frame was rendered for) with a modelled
// tracker, a fixed render + display latency and each prediction mode, over all frames and
// in the window after each saccade's landing (where the fovea should already be). Virtual time, deterministic. docs/gaze.md
// ("Prediction, measured"); the table comes from bench/predict_table.cpp.
#include <cstddef>
#include <string_view>

#include "fovea/devices/gaze.hpp"
#include "fovea/devices/tracker_model.hpp"

namespace fovea::devices {

struct CompensationParams {
  TrackerParams tracker = tracker_preset("fove0");
  core::TimeNs latency_ns = 30'000'000;  // the gaze is read this long before the frame is shown
  double display_hz = 90;
  core::TimeNs horizon_ns = SourceOptions{}.horizon_ns;  // as a gaze source predicts by default
  core::TimeNs after_saccade_ns = 150'000'000;  // "after a saccade": from its landing on, this long
  double seconds = 10;                          // frames shown from 0 to this
  void validate() const;                        // throws core::InputError
};

struct FovealError {
  PredictMode mode = PredictMode::Linear;
  std::size_t frames = 0;        // frames with a true gaze and a rendered-for gaze
  std::size_t saccades = 0;      // of the true gaze (SaccadeOnsetDetector), landed by `seconds`
  std::size_t post_frames = 0;   // frames within after_saccade_ns of a landing
  // Over the post-saccade frames, degrees.
  double mean_deg = 0, p50_deg = 0, p95_deg = 0, max_deg = 0;
  double over_2deg = 0;          // fraction of post-saccade frames with an error above 2°
  double all_mean_deg = 0;       // over all frames
};

// `truth_uri`: a recording or synthetic gaze (the true eye; its own prediction keys are
// ignored), seen through p.tracker. Each frame k is shown at k/display_hz; its gaze is what
// the foveation gaze (loss policy included) gives from the samples delivered by
// show − latency, predicted to the show time with `mode`. Throws core::InputError.
FovealError measure_foveal_error(std::string_view truth_uri, PredictMode mode, const CompensationParams& p,
                                 const SourceOptions& opt = {});

}  // namespace fovea::devices
