#pragma once
// The one path from an eye tracker to the foveation. A FoveationGaze owns a gaze source
// (with its optional filters and prediction), the time base that maps the caller's clock
// onto the source's timeline, and the loss policy; each use reports where each eye's fovea
// goes and the true times of the newest real sample behind it. `fovea render`, `fovea view`,
// the OpenXR layer and the runtime all foveate through it (docs/gaze.md).
#include <array>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>

#include "fovea/devices/gaze.hpp"

namespace fovea::devices {

// What the fovea does while an eye is not tracked (blink, dropout, stale or lost device):
// it stays on the last tracked direction for hold_ns, then eases (smoothstep) to `rest`
// over ease_ns, and returns to the tracker at its next tracked sample. hold_ns covers the
// longest typical blink (100–400 ms) and the longest saccade of a ±20° field (2.2·40 + 21 ms
// = 109 ms); sources in docs/gaze.md.
struct LossPolicy {
  core::TimeNs hold_ns = 400'000'000;
  core::TimeNs ease_ns = 300'000'000;
  glm::dvec3 rest{0, 0, -1};  // fixed foveation: the view's forward direction
};

enum class FoveaState : std::uint8_t {
  Tracking,  // dir is this use's measurement (or its prediction to the query time)
  Holding,   // dir is the last tracked direction
  Easing,    // dir is on its way from the last tracked direction to `rest`
  Resting,   // dir is `rest`: never tracked, or lost for hold_ns + ease_ns
};

struct FoveaEye {
  glm::dvec3 dir{0, 0, -1};  // where to foveate: unit, view space
  double confidence = 0;     // of the measurement (0 unless Tracking)
  std::uint32_t flags = kLost;  // the tracker's flags for this eye at this use
  FoveaState state = FoveaState::Resting;
  bool tracked() const { return state == FoveaState::Tracking; }
};

// One use of the gaze. Times are on the caller's clock (the one at() is asked on).
struct FoveaGaze {
  FoveaEye combined, left, right;  // an eye without its own measurement follows the combined gaze
  Motion motion = Motion::Unknown;
  bool has_sample = false;      // a real sample had been measured by query_ns (else no times)
  core::TimeNs query_ns = 0;    // the time asked for (e.g. the frame's display time)
  core::TimeNs sample_ns = 0;   // when the newest real sample used was measured (≤ query_ns)
  core::TimeNs device_ns = 0;   // that sample's own stamp (tracker clock or recording file)
  core::TimeNs receive_ns = 0;  // when the host received it (recordings: = sample_ns; a tracker model: its delivery)
  core::TimeNs read_ns = 0;     // host monotonic time at which this use read the source

  const FoveaEye& eye(core::Eye e) const { return e == core::Eye::Left ? left : right; }
};

class FoveationGaze {
 public:
  // Throws core::InputError for a bad policy or (second form) a URI the devices module
  // cannot open.
  explicit FoveationGaze(std::unique_ptr<GazeSource> source, const LossPolicy& policy = {});
  FoveationGaze(std::string_view uri, const SourceOptions& options, const LossPolicy& policy = {});
  ~FoveationGaze();

  // The time base. Live sources run on the host monotonic clock, so the caller's clock must
  // be that clock. Recorded and synthetic sources start at `epoch_ns` on the caller's clock:
  // set it, or the first use's query time is taken.
  bool live() const { return source_->is_live(); }
  void set_epoch(core::TimeNs epoch_ns);

  // The fovea at time t (caller's clock) from the samples measured by t.
  FoveaGaze at(core::TimeNs t) { return read(t, t); }
  // The fovea for target_ns (e.g. a frame's display time) as read at read_ns: from the
  // samples available by min(read_ns, target_ns) only, predicted to target_ns when the
  // source predicts (GazeSource::read_at); query_ns is target_ns.
  FoveaGaze read(core::TimeNs read_ns, core::TimeNs target_ns);
  // The true eye at t (caller's clock; GazeSource::truth_at): t_ns kNoSample when unknown.
  GazeSample truth_at(core::TimeNs t);
  // For programs whose frames carry a virtual time (frame index / refresh rate, from 0):
  // recordings play on it, live sources are read at the host clock now.
  FoveaGaze at_frame_time(core::TimeNs frame_ns) { return at(live() ? core::now_ns() : frame_ns); }
  // The fovea at time t from a measurement made elsewhere (the OpenXR eye-gaze action);
  // `s.t_ns` on the caller's clock, kNoSample when nothing was measured.
  FoveaGaze use(core::TimeNs t, const GazeSample& s);

  const LossPolicy& policy() const { return policy_; }
  std::string describe() const { return source_->describe(); }

 private:
  struct Track {
    glm::dvec3 dir{0, 0, -1};
    core::TimeNs t_ns = 0;  // measurement time of dir
    bool seen = false;
  };
  FoveaEye follow(Track& track, const EyeGaze& m, core::TimeNs sample_ns, core::TimeNs t) const;
  FoveaGaze apply(core::TimeNs t, const GazeSample& s, core::TimeNs offset);

  std::unique_ptr<GazeSource> source_;
  LossPolicy policy_;
  std::optional<core::TimeNs> epoch_;
  std::array<Track, 3> tracks_;  // combined, left, right
  std::mutex mutex_;
};

}  // namespace fovea::devices
