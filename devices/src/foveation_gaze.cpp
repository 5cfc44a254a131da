#include "fovea/devices/foveation_gaze.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"

namespace fovea::devices {
namespace {

bool usable(const EyeGaze& g) {
  const glm::dvec3& d = g.dir;
  return g.tracked() && std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z) && glm::length(d) > 0.5;
}

}  // namespace

FoveationGaze::FoveationGaze(std::unique_ptr<GazeSource> source, const LossPolicy& policy)
    : source_(std::move(source)), policy_(policy) {
  if (!source_) throw core::InputError("foveation gaze: no gaze source");
  const glm::dvec3& r = policy_.rest;
  if (policy_.hold_ns < 0 || policy_.ease_ns < 0 || !std::isfinite(r.x + r.y + r.z) || glm::length(r) < 1e-9)
    throw core::InputError("foveation gaze: the loss policy needs hold and ease times >= 0 and a rest direction");
  policy_.rest = glm::normalize(r);
}

FoveationGaze::FoveationGaze(std::string_view uri, const SourceOptions& options, const LossPolicy& policy)
    : FoveationGaze(open_gaze_source(uri, options), policy) {}

FoveationGaze::~FoveationGaze() = default;

void FoveationGaze::set_epoch(core::TimeNs epoch_ns) {
  std::lock_guard lock(mutex_);
  epoch_ = epoch_ns;
}

FoveaEye FoveationGaze::follow(Track& track, const EyeGaze& m, core::TimeNs sample_ns, core::TimeNs t) const {
  FoveaEye e;
  e.flags = m.flags;
  if (usable(m)) {
    track = {glm::normalize(m.dir), sample_ns, true};
    e.dir = track.dir;
    e.confidence = m.confidence;
    e.state = FoveaState::Tracking;
    return e;
  }
  e.dir = policy_.rest;
  if (!track.seen) return e;  // Resting
  // Time since the last tracked measurement, so a stale device counts from its last sample.
  const core::TimeNs since = std::max<core::TimeNs>(0, t - track.t_ns);
  if (since <= policy_.hold_ns) {
    e.dir = track.dir;
    e.state = FoveaState::Holding;
    return e;
  }
  const double u = policy_.ease_ns > 0
                       ? std::clamp(static_cast<double>(since - policy_.hold_ns) / static_cast<double>(policy_.ease_ns), 0.0, 1.0)
                       : 1.0;
  if (u >= 1) return e;  // Resting
  const double w = u * u * (3 - 2 * u);  // smoothstep: no velocity jump at either end
  const glm::dvec3 d = (1 - w) * track.dir + w * policy_.rest;
  e.dir = glm::length(d) > 1e-9 ? glm::normalize(d) : policy_.rest;
  e.state = FoveaState::Easing;
  return e;
}

FoveaGaze FoveationGaze::apply(core::TimeNs t, const GazeSample& s, core::TimeNs offset) {
  FoveaGaze g;
  g.query_ns = t;
  g.motion = s.motion;
  g.has_sample = s.t_ns != kNoSample;
  if (g.has_sample) {
    g.sample_ns = s.t_ns + offset;
    g.device_ns = s.device_time_ns;
    // Recordings report receipt at measurement; a modelled tracker its delivery time.
    g.receive_ns = s.host_time_ns + offset;
  }
  const core::TimeNs sample_ns = g.has_sample ? g.sample_ns : t;
  g.combined = follow(tracks_[0], s.combined, sample_ns, t);
  // An eye without its own measurement follows the combined gaze (e.g. a monocular tracker).
  g.left = follow(tracks_[1], s.left.tracked() ? s.left : s.combined, sample_ns, t);
  g.right = follow(tracks_[2], s.right.tracked() ? s.right : s.combined, sample_ns, t);
  g.read_ns = core::now_ns();
  return g;
}

FoveaGaze FoveationGaze::read(core::TimeNs read_ns, core::TimeNs target_ns) {
  std::lock_guard lock(mutex_);
  const bool is_live = live();
  if (!is_live && !epoch_) epoch_ = std::min(read_ns, target_ns);
  const core::TimeNs offset = is_live ? 0 : *epoch_;
  return apply(target_ns, source_->read_at(read_ns - offset, target_ns - offset), offset);
}

GazeSample FoveationGaze::truth_at(core::TimeNs t) {
  std::lock_guard lock(mutex_);
  const bool is_live = live();
  if (!is_live && !epoch_) epoch_ = t;
  const core::TimeNs offset = is_live ? 0 : *epoch_;
  GazeSample s = source_->truth_at(t - offset);
  if (s.t_ns != kNoSample) {
    s.t_ns += offset;
    s.host_time_ns += offset;
  }
  return s;
}

FoveaGaze FoveationGaze::use(core::TimeNs t, const GazeSample& s) {
  std::lock_guard lock(mutex_);
  return apply(t, s, 0);
}

}  // namespace fovea::devices
