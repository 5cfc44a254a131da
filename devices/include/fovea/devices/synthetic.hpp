#pragma once
// Synthetic gaze, reproducible from a seed: fixations, main-sequence saccades,
// microsaccades, smooth pursuit with catch-up saccades, blinks, burst dropouts and
// coloured tracker noise. Constants and their sources: docs/gaze.md ("Synthetic gaze").
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "fovea/devices/gaze.hpp"

namespace fovea::devices {

enum class SynthTask { Reading, Search, Pursuit, FixationGrid };
SynthTask parse_synth_task(std::string_view s);  // "reading" | "search" | "pursuit" | "fixation-grid"
const char* synth_task_name(SynthTask t);

struct SynthParams {
  std::uint64_t seed = 1;
  SynthTask task = SynthTask::Search;
  double rate_hz = 120;          // 60..1000
  double seconds = 0;            // <= 0: endless
  double noise_deg = 0.05;       // tracker noise, RMS per axis and eye
  double noise_color = 0.0;      // AR(1) coefficient in [0, 0.99): 0 white, towards 1 "pinker"
  double dropout_per_s = 0.05;   // burst dropouts (onsets per second)
  double fixation_distance_m = 1.0;  // vergence: both eyes look at a point this far away
  double ipd_m = 0.063;
  void validate() const;  // throws core::InputError
};

// Main-sequence model (see docs/gaze.md): duration D = 2.2·A + 21 ms (Carpenter 1988),
// peak velocity Vp = Vmax·(1 − e^(−A/C)) with Vmax = 700 °/s, C = 14° (Baloh 1975).
namespace main_sequence {
constexpr double kVmaxDegS = 700, kCDeg = 14, kSlopeMsPerDeg = 2.2, kInterceptMs = 21;
double duration_ms(double amplitude_deg);
double peak_velocity_deg_s(double amplitude_deg);
}  // namespace main_sequence

struct SynthEvent {
  enum Kind { Fixation, Saccade, Microsaccade, CatchUpSaccade, Blink, Dropout } kind;
  core::TimeNs start_ns = 0, end_ns = 0;
  double amplitude_deg = 0, peak_velocity_deg_s = 0;  // saccades
};
const char* synth_event_name(SynthEvent::Kind k);

class SyntheticStream final : public SampleStream {
 public:
  explicit SyntheticStream(const SynthParams& p);
  ~SyntheticStream() override;
  bool next(GazeSample& out) override;
  bool rewindable() const override { return true; }
  void rewind() override;
  std::string describe() const override;
  // Ground truth: called once per finished event, in order of completion.
  void on_event(std::function<void(const SynthEvent&)> fn);
  const SynthParams& params() const { return params_; }

 private:
  struct State;
  SynthParams params_;
  std::unique_ptr<State> s_;
  std::function<void(const SynthEvent&)> log_;
};

}  // namespace fovea::devices
