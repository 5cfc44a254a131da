#include "gaze.hpp"

#include <algorithm>

#include "fovea/devices/foveation_gaze.hpp"

namespace fovea::runtime {

GazeTracker::GazeTracker(const std::string& uri, const core::DisplayPreset& display) {
  devices::SourceOptions opt;
  opt.display = display;
  gaze_ = std::make_unique<devices::FoveationGaze>(uri, opt);
}

GazeTracker::~GazeTracker() = default;

GazeSample GazeTracker::read(core::TimeNs read_ns, core::TimeNs target_ns, core::TimeNs epoch_ns) {
  gaze_->set_epoch(epoch_ns);
  const devices::FoveaGaze f = gaze_->read(read_ns, target_ns);
  GazeSample g;
  g.valid = f.combined.tracked();
  if (g.valid) g.dir = f.combined.dir;
  if (f.has_sample) {
    g.sample_ns = f.sample_ns;
    g.receive_ns = f.receive_ns;
  }
  g.read_ns = std::min(read_ns, target_ns);
  return g;
}

std::optional<glm::dvec3> GazeTracker::truth_at(core::TimeNs t, core::TimeNs epoch_ns) {
  gaze_->set_epoch(epoch_ns);
  const devices::GazeSample s = gaze_->truth_at(t);
  if (s.t_ns == devices::kNoSample || !s.combined.tracked()) return std::nullopt;
  return s.combined.dir;
}

std::string GazeTracker::describe() const { return gaze_->describe(); }

}  // namespace fovea::runtime
