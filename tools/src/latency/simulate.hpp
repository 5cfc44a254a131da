#pragma once
// `fovea latency`'s scenario in virtual time (docs/latency.md): a true eye behind a modelled
// eye tracker, an application paced by the display model (xrWaitFrame's FramePacer) that
// reads the gaze when it wakes, renders for a given cost and submits; the display model
// shows the frame at the first vsync it makes and lights it per eye and region. Every frame
// gives a timing record with the true gaze at its photon time; every vsync the foveal error
// of the frame on the panel. Deterministic: same inputs, same records.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "fovea/core/grid_hold.hpp"
#include "fovea/devices/foveation_gaze.hpp"
#include "fovea/devices/tracker_model.hpp"
#include "fovea/xrcommon/display_model.hpp"
#include "fovea/xrcommon/timing_record.hpp"

namespace fovea::latency {

// The tracker over the true eye: a preset with options on top (unset: the preset's), plus an
// injected latency added to every sample's delivery.
struct TrackerChoice {
  std::string preset = "fove0";
  std::optional<core::TimeNs> delay_ns, jitter_ns;
  std::optional<double> rate_hz;
  core::TimeNs inject_ns = 0;
};
// The true eye from `gaze_uri` (a recording or synthetic gaze; tracker keys belong to
// `choice`, an error in the URI) behind the tracker. Throws core::InputError.
std::unique_ptr<devices::TrackerModel> open_tracker(const std::string& gaze_uri, const TrackerChoice& choice,
                                                    const devices::SourceOptions& opt);

// What rendering one frame cost: the virtual time it takes, and its stages.
struct FrameWork {
  core::TimeNs cost_ns = 0;
  std::vector<std::pair<std::string, double>> cpu_ms, gpu_ms;
};
// Renders frame `index` foveated for `gaze`, as read at the frame's wake (its eyes' view-space
// directions; the frame pipeline holds each eye's grid through a fixational drift).
using RenderFn = std::function<FrameWork(std::int64_t index, const devices::FoveaGaze& gaze)>;

// Gaze compensation is the tracker's: its source options' predict mode and horizon
// (open_tracker) predict the delivered samples to each frame's display time.
struct Scenario {
  xrcommon::DisplayParams display;
  core::TimeNs duration_ns = 2'000'000'000;  // frames are started until this time
  // The frame pipeline's grid hold (core::GridHold::radius_for_margin of the distribution's
  // fovea margin): what each frame's grid was laid out for.
  double hold_deg = core::GridHold::kHoldDeg;
};

struct FrameTruth {
  std::array<glm::dvec3, 2> fovea{};  // the gaze each eye was rendered with
  std::array<std::optional<glm::dvec3>, 2> truth;  // each eye's true gaze at its photon time (mid row); none in a blink
};

// The panel at one vsync: the frame it shows and that frame's foveal error at the vsync's
// photon time (left eye, mid row; none while the true eye is not tracked).
struct Shown {
  std::int64_t vsync = 0;
  core::TimeNs vsync_ns = 0, photon_ns = 0;
  std::int64_t frame = 0;
  std::optional<double> error_deg;
};

// A saccade of the true eye (I-VT on the truth at its own sample times).
struct Saccade {
  core::TimeNs onset_ns = 0, offset_ns = 0;
  double amplitude_deg = 0;
};

struct Simulation {
  std::vector<xrcommon::TimingRecord> records;  // one per frame, clock "virtual"
  std::vector<FrameTruth> frames;
  std::vector<Shown> shown;                     // one per vsync from the first frame's on
  std::vector<Saccade> saccades;
};

Simulation simulate(devices::TrackerModel& tracker, const Scenario& s, const RenderFn& render);

// Post-saccade recovery, ms: for each saccade of at least `min_amplitude_deg`, from its end
// to the first photon time at which the panel's foveal error is below `threshold_deg`.
std::vector<double> recovery_ms(const Simulation& sim, double threshold_deg = 2.0, double min_amplitude_deg = 2.0);

// The panel's foveal errors (degrees) at the vsyncs whose photon time lies within
// `window_ns` after the end of a saccade of at least `min_amplitude_deg`: where the fovea
// should already be on the new target, and what gaze compensation is for.
std::vector<double> post_saccade_errors(const Simulation& sim, core::TimeNs window_ns = 150'000'000,
                                        double min_amplitude_deg = 2.0);

}  // namespace fovea::latency
