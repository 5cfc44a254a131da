#include "gaze_options.hpp"

#include "fovea/devices/readers.hpp"

namespace fovea::fuzz {

const devices::SourceOptions& gaze_options() {
  static const devices::SourceOptions opt;
  return opt;
}

void drain_recording(const std::string& path, std::string_view format) {
  devices::SourceOptions opt = gaze_options();
  opt.format = std::string(format);
  const auto r = devices::open_reader(path, opt);
  devices::GazeSample s;
  while (r->next(s)) {
  }
  (void)r->metadata_json();
  (void)r->stats().dropped_total();
}

}  // namespace fovea::fuzz
