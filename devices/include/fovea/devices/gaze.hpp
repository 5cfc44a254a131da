#pragma once
// Gaze samples and the one interface every eye-tracker source implements.
// Directions are unit vectors in view space (OpenXR: -Z forward, +Y up, +X right).
// Times are int64 nanoseconds. Sources are opened from URI-like strings, see
// open_gaze_source() and docs/gaze.md.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "fovea/core/clock.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/view.hpp"

namespace fovea::devices {

// Validity flags. Exactly one of them is set on every sample produced by a source.
enum GazeFlag : std::uint32_t {
  kTracked = 1u,  // the direction is a measurement
  kBlink = 2u,    // eye closed; the direction is not a measurement
  kLost = 4u,     // no measurement (dropout, not worn, out of range, no data)
};

struct EyeGaze {
  glm::dvec3 dir{0, 0, -1};  // unit, view space
  double confidence = 0;     // [0, 1]
  std::uint32_t flags = kLost;
  bool tracked() const { return (flags & kTracked) != 0; }
};

// Eye-movement class of a sample, set by the I-VT filter stage (filters.hpp); Unknown otherwise.
enum class Motion : std::uint8_t { Unknown, Fixation, Saccade };

// GazeSample::t_ns when no sample had been measured by the time asked for.
inline constexpr core::TimeNs kNoSample = INT64_MIN;

struct GazeSample {
  // On the source's timeline: replays and synthetic gaze count from their first sample
  // (t = 0); live devices use the host monotonic clock (device time mapped through the
  // estimated, drift-corrected clock offset).
  core::TimeNs t_ns = 0;
  core::TimeNs device_time_ns = 0;  // as stamped by the tracker / the recording
  core::TimeNs host_time_ns = 0;    // host monotonic receive time (replays: = t_ns)
  EyeGaze combined, left, right;
  Motion motion = Motion::Unknown;

  bool tracked() const { return combined.tracked(); }
  const EyeGaze& eye(core::Eye e) const { return e == core::Eye::Left ? left : right; }
  EyeGaze& eye(core::Eye e) { return e == core::Eye::Left ? left : right; }
};

// An ordered stream of samples, pulled one at a time. Replays and synthetic gaze are
// finite and rewindable; live devices return false from next() when nothing new arrived.
class SampleStream {
 public:
  virtual ~SampleStream() = default;
  virtual bool next(GazeSample& out) = 0;
  virtual bool rewindable() const { return false; }
  virtual void rewind();  // throws std::logic_error unless rewindable()
  virtual bool live() const { return false; }
  virtual std::string describe() const = 0;
};

// How a source predicts its newest sample to the time asked for (URI key predict=):
// none; linear (GazePredictor: constant velocity, held across a saccade until its peak);
// landing (as linear, but a saccade in flight goes to its fitted landing point,
// saccade_predict.hpp).
enum class PredictMode : std::uint8_t { None, Linear, Landing };
PredictMode parse_predict_mode(std::string_view s);  // throws core::InputError
const char* predict_mode_name(PredictMode m);

// Geometry used to turn 2D gaze coordinates (display pixels, scene-camera pixels,
// micrometres on a calibrated screen, normalised coordinates) into view directions:
// a pinhole View (field of view + raster). Normalised inputs are scaled to the raster.
struct SourceOptions {
  core::DisplayPreset display = core::load_display(core::kDefaultDisplay);
  // The 2D surface the gaze coordinates refer to; default: the display's left view.
  std::optional<core::View> screen;
  std::string format;   // replay: force a format instead of auto-detection
  double speed = 1.0;   // replay: timeline speed factor
  bool loop = false;    // replay: wrap around at the end
  PredictMode predict = PredictMode::Linear;
  core::TimeNs horizon_ns = 20'000'000;   // prediction never goes further past the newest sample (0: off)
  core::TimeNs max_gap_ns = 100'000'000;  // a newest sample older than this is stale (result: lost)
  core::TimeNs window_ns = 2'000'000'000; // history kept for sample_at()
  double min_confidence = 0.6;            // formats with confidence: below this -> lost
  // Filter stages applied to the stream, in order: "ivt", "oneeuro" (filters.hpp).
  std::string filters;
  std::string raw_capture;  // HID sources: also write the raw device traffic here (docs/hid.md)

  bool predicts() const { return predict != PredictMode::None && horizon_ns > 0; }
  core::View screen_view() const { return screen ? *screen : display.view(core::Eye::Left); }
};

class GazeSource {
 public:
  virtual ~GazeSource() = default;
  // The newest sample available now; never blocks.
  virtual GazeSample latest() = 0;
  // The gaze at time t on the source's timeline from the samples measured at or before t
  // (never a later one): the newest of them, its direction predicted to t (at most
  // horizon_ns) when prediction is on. t_ns of the result is the newest real sample's time
  // on the same timeline, never t; before the first sample t_ns is kNoSample and the
  // result is lost. A newest sample older than max_gap_ns is stale: flagged lost.
  virtual GazeSample sample_at(core::TimeNs t) = 0;
  // The gaze a renderer reading at `read_ns` has for `target_ns` (e.g. its frame's display
  // time): the newest sample available by min(read_ns, target_ns) — measured by then, or for
  // a modelled tracker delivered by then — never a later one, its direction predicted to
  // target_ns from those samples only when prediction is on. sample_at(t) is read_at(t, t).
  // Sources that do not predict hold the newest sample.
  virtual GazeSample read_at(core::TimeNs read_ns, core::TimeNs target_ns) {
    return sample_at(std::min(read_ns, target_ns));
  }
  // The true eye at t, for measuring what latency costs: a recording's or synthetic gaze's
  // own sample at t (no prediction), a tracker model's ground truth (no delay, no noise).
  // t_ns is kNoSample when the source knows no truth (live devices).
  virtual GazeSample truth_at(core::TimeNs t);
  // Live sources stamp samples with the host monotonic clock; recorded and synthetic ones
  // count from their first sample. Set by the source kind, never guessed from its name.
  virtual bool is_live() const = 0;
  virtual std::string describe() const = 0;
};

// "replay:FILE[?format=F&speed=S&loop=1]", "synthetic:SEED[?task=T&rate=HZ&seconds=S&...]",
// "hid:[VID:PID|path]", "usb:[VID:PID]", "hid-capture:FILE". A plain path is a replay.
// Query keys common to all: filters=..., horizon_ms=..., min_confidence=...; recordings and
// synthetic gaze also take a tracker model: tracker=PRESET, tracker_*=... (tracker_model.hpp).
// Throws core::InputError for a malformed URI, an unknown scheme or an unusable input.
std::unique_ptr<GazeSource> open_gaze_source(std::string_view uri, const SourceOptions& opt);

// The stream behind a URI (before the timeline), for tools that walk every sample.
std::unique_ptr<SampleStream> open_sample_stream(std::string_view uri, const SourceOptions& opt);

// Helpers shared by sources: normalised mean of the tracked eyes (combined gaze).
EyeGaze combine_eyes(const EyeGaze& left, const EyeGaze& right);
// Interpolation between two samples (normalised lerp of the directions); the flags of
// the nearer one unless both are tracked.
GazeSample interpolate(const GazeSample& a, const GazeSample& b, core::TimeNs t);

}  // namespace fovea::devices
