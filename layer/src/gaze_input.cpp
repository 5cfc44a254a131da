#include "gaze_input.hpp"

namespace fovea::layer {
namespace {

devices::SourceOptions options(const core::DisplayPreset& display) {
  devices::SourceOptions o;
  o.display = display;
  return o;
}

}  // namespace

LayerGaze::LayerGaze(const std::string& uri, const core::DisplayPreset& display) : gaze_(uri, options(display)) {}

devices::FoveaGaze LayerGaze::frame(std::int64_t display_time_ns, const ActionGaze* action) {
  if (!action) return gaze_.at(display_time_ns);
  // The action gives the combined gaze in head space; each eye follows it (views parallel
  // to the head). Without a reported sample time the measurement has no time of its own.
  devices::GazeSample s;
  s.t_ns = action->sample_time_ns > 0 ? action->sample_time_ns : devices::kNoSample;
  s.device_time_ns = s.host_time_ns = action->sample_time_ns;
  if (action->dir) {
    s.combined.dir = *action->dir;
    s.combined.flags = devices::kTracked;
    s.combined.confidence = 1;
  }
  return gaze_.use(display_time_ns, s);
}

}  // namespace fovea::layer
