#pragma once
// A modelled eye tracker over a ground-truth gaze source (the true eye): it samples the truth
// at its own rate, delivers each sample a fixed delay (plus bounded jitter) after it was
// measured, with angular noise, burst dropouts, blinks and optional loss during saccades.
// Runs in virtual time (deterministic: replays, tests, `fovea latency`) or on the host clock
// (a thread delivering samples, so live paths run without hardware). Presets and the sources
// of their figures: docs/gaze.md ("Tracker model"). URI keys: tracker=PRESET, tracker_*.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

#include "fovea/devices/filters.hpp"
#include "fovea/devices/gaze.hpp"

namespace fovea::devices {

struct TrackerParams {
  std::string name = "ideal";       // the preset it started from (describe())
  double rate_hz = 1000;            // sample k is measured at round(k·10⁹/rate) ns
  core::TimeNs delay_ns = 0;        // measured at t → delivered at t + delay (+ jitter)
  core::TimeNs jitter_ns = 0;       // extra delivery delay, uniform in [0, jitter]; order kept
  double noise_deg = 0;             // angular measurement noise per eye, RMS (isotropic Gaussian)
  double dropout = 0;               // long-run fraction of samples lost in dropout bursts
  core::TimeNs burst_ns = 0;        // mean dropout burst length (geometric in samples)
  double saccade_loss_deg_s = 0;    // lost while the true eye moves faster than this (0: off)
  std::uint64_t seed = 1;
  bool host_clock = false;          // deliver on the host monotonic clock from a thread
  void validate() const;            // throws core::InputError
};

// "fove0" (Fove-0 figures, docs/gaze.md) or "ideal" (1 kHz, no delay, no errors).
TrackerParams tracker_preset(std::string_view name);

class TrackerModel final : public GazeSource {
 public:
  // `truth` must be a recording or synthetic gaze (not live), read without prediction.
  // opt: horizon_ns (prediction of the delivered samples), max_gap_ns, window_ns.
  TrackerModel(std::unique_ptr<GazeSource> truth, const TrackerParams& params, const SourceOptions& opt);
  ~TrackerModel() override;

  GazeSample latest() override;
  // From the samples delivered by t (never one delivered later): the newest; t_ns is its
  // measurement time, host_time_ns its delivery time, device_time_ns its measurement time on
  // the tracker's clock (from 0). Stale (lost) when nothing was delivered for max_gap_ns.
  GazeSample sample_at(core::TimeNs t) override { return read_at(t, t); }
  // As sample_at(min(read, target)), its direction predicted to target_ns from the samples
  // delivered by then (never from one delivered later).
  GazeSample read_at(core::TimeNs read_ns, core::TimeNs target_ns) override;
  bool is_live() const override { return params_.host_clock; }
  std::string describe() const override;

  // The true eye at time t on this source's timeline (host clock: from the model's start).
  GazeSample truth_at(core::TimeNs t) override;
  const TrackerParams& params() const { return params_; }
  // Host clock: the host time of the tracker's t = 0 (0 in virtual time).
  core::TimeNs epoch_ns() const { return epoch_; }

 private:
  struct Generator;
  void deliver_loop();
  void restart();

  std::unique_ptr<GazeSource> truth_;
  TrackerParams params_;
  SourceOptions opt_;
  std::unique_ptr<Generator> gen_;
  GazePredictor predictor_;
  std::deque<GazeSample> win_;  // delivered samples, delivery order (= measurement order)
  bool trimmed_ = false;
  core::TimeNs epoch_ = 0, opened_ns_ = 0;
  std::mutex mutex_, truth_mutex_;
  std::condition_variable wake_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace fovea::devices
