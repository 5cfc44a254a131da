#include "gaze_input.hpp"

#include "log.hpp"

namespace fovea::layer {
namespace {

// No eye tracker configured: a source that never measures, so the loss policy keeps the
// fovea at rest, the view's forward direction (fixed foveation at the view centre).
class NoGaze final : public devices::GazeSource {
 public:
  devices::GazeSample latest() override { return none(); }
  devices::GazeSample sample_at(core::TimeNs) override { return none(); }
  bool is_live() const override { return false; }
  std::string describe() const override { return "none (fixed foveation at the view centre)"; }

 private:
  static devices::GazeSample none() {
    devices::GazeSample s;
    s.t_ns = devices::kNoSample;
    return s;
  }
};

devices::SourceOptions options(const core::DisplayPreset& display) {
  devices::SourceOptions o;
  o.display = display;
  return o;
}

std::unique_ptr<devices::GazeSource> source(const std::string& uri, const core::DisplayPreset& display) {
  if (!uri.empty()) return devices::open_gaze_source(uri, options(display));
  FOVEA_LAYER_WARN("no gaze source configured (FOVEA_GAZE or the configuration's \"gaze\"): unless the runtime's "
                   "eye-gaze action is used, the fovea stays fixed at the view centre");
  return std::make_unique<NoGaze>();
}

}  // namespace

LayerGaze::LayerGaze(const std::string& uri, const core::DisplayPreset& display) : gaze_(source(uri, display)) {}

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
