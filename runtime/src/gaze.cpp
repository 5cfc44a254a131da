#include "gaze.hpp"

#include <cmath>

#include <glm/geometric.hpp>

#include "fovea/devices/gaze.hpp"

namespace fovea::runtime {

GazeTracker::GazeTracker(const std::string& uri, const core::DisplayPreset& display) {
  devices::SourceOptions opt;
  opt.display = display;
  source_ = devices::open_gaze_source(uri, opt);
  live_ = uri.rfind("hid:", 0) == 0 || uri.rfind("usb:", 0) == 0;
}

GazeTracker::~GazeTracker() = default;

GazeSample GazeTracker::sample_at(core::TimeNs t_ns, core::TimeNs epoch_ns) {
  const core::TimeNs offset = live_ ? 0 : epoch_ns;
  const devices::GazeSample s = source_->sample_at(std::max<core::TimeNs>(0, t_ns - offset));
  GazeSample g;
  const glm::dvec3 d = s.combined.dir;
  g.valid = s.tracked() && std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z) && glm::length(d) > 0.5;
  if (g.valid) g.dir = glm::normalize(d);
  g.sample_ns = s.t_ns + offset;
  return g;
}

std::string GazeTracker::describe() const { return source_->describe(); }

}  // namespace fovea::runtime
