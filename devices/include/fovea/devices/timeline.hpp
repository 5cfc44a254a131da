#pragma once
// A GazeSource over any SampleStream: keeps a bounded window of recent samples and answers
// sample_at() from the newest sample at or before the time asked for. Recorded streams
// (replay, synthetic) are played on a timeline starting at their first sample (t = 0),
// scaled by `speed`, optionally looped; seeking backwards before the window re-reads the
// stream from its start; past the end of a recording its last sample stays. Between
// samples the direction is predicted to the time asked for (GazePredictor, at most
// horizon_ns; horizon_ns = 0 holds the newest sample); read_at() predicts to a later target
// from the samples measured by the read time.
#include <deque>
#include <memory>
#include <mutex>

#include "fovea/devices/filters.hpp"
#include "fovea/devices/gaze.hpp"

namespace fovea::devices {

class TimelineSource final : public GazeSource {
 public:
  TimelineSource(std::unique_ptr<SampleStream> stream, const SourceOptions& opt);
  GazeSample latest() override;
  GazeSample sample_at(core::TimeNs t) override { return read_at(t, t); }
  GazeSample read_at(core::TimeNs read_ns, core::TimeNs target_ns) override;
  // Recorded and synthetic streams: the newest sample at t as it is (live ones: unknown).
  GazeSample truth_at(core::TimeNs t) override;
  bool is_live() const override { return stream_->live(); }
  std::string describe() const override { return stream_->describe(); }
  // Samples currently held (bounded by window_ns); for tests of the memory bound.
  std::size_t window_size() const { return win_.size(); }

 private:
  void pull_until(core::TimeNs t);
  void restart();
  // The newest sample at recording time tt, predicted `ahead_ns` past tt when `predict`.
  GazeSample at_recording_time(core::TimeNs tt, core::TimeNs ahead_ns, bool predict);
  GazeSample on_caller_timeline(core::TimeNs t, core::TimeNs ahead_ns, bool predict);

  std::unique_ptr<SampleStream> stream_;
  SourceOptions opt_;
  std::deque<GazeSample> win_;
  bool ended_ = false, trimmed_ = false;
  core::TimeNs period_ = -1;  // loop period once the end is known
  core::TimeNs loop_base_ = 0;  // recording time of the current loop's start (k · period_)
  core::TimeNs opened_ns_ = 0;
  GazePredictor predictor_;
  std::mutex mutex_;
};

}  // namespace fovea::devices
