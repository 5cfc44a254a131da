#include "gaze.hpp"

#include "fovea/devices/foveation_gaze.hpp"

namespace fovea::runtime {

GazeTracker::GazeTracker(const std::string& uri, const core::DisplayPreset& display) {
  devices::SourceOptions opt;
  opt.display = display;
  gaze_ = std::make_unique<devices::FoveationGaze>(uri, opt);
}

GazeTracker::~GazeTracker() = default;

GazeSample GazeTracker::sample_at(core::TimeNs t_ns, core::TimeNs epoch_ns) {
  gaze_->set_epoch(epoch_ns);
  const devices::FoveaGaze f = gaze_->at(t_ns);
  GazeSample g;
  g.valid = f.combined.tracked();
  if (g.valid) g.dir = f.combined.dir;
  if (f.has_sample) {
    g.sample_ns = f.sample_ns;
    g.receive_ns = f.receive_ns;
  }
  g.read_ns = f.read_ns;
  return g;
}

std::string GazeTracker::describe() const { return gaze_->describe(); }

}  // namespace fovea::runtime
