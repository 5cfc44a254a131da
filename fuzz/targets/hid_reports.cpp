// HID report descriptors and the reports they describe. Input layout: a 16-bit little-
// endian descriptor length, the descriptor, then reports, each prefixed by its length
// byte (the first byte of a report decides input or feature: even input, odd feature).
#include <algorithm>

#include "../harness.hpp"
#include "fovea/devices/hid_eye_tracker.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "../gaze_options.hpp"

namespace hid = fovea::devices::hid;

FOVEA_FUZZ_TARGET(hid_reports) {
  if (data.size() < 2) return;
  const std::size_t len = std::min<std::size_t>(data[0] | (data[1] << 8), data.size() - 2);
  const auto desc = data.subspan(2, len);
  (void)hid::parse_descriptor(desc);
  const hid::EyeTrackerCodec codec(desc);
  (void)codec.startup_feature_ids();
  (void)codec.mode_request(3);
  hid::GazeMapper mapper(codec, fovea::fuzz::gaze_options().screen_view());
  auto rest = data.subspan(2 + len);
  while (rest.size() > 1) {
    const std::size_t n = std::min<std::size_t>(rest[0] >> 1, rest.size() - 1);
    const auto report = rest.subspan(1, n);
    if (rest[0] & 1) {
      mapper.feature(report);
    } else {
      fovea::devices::GazeSample g;
      std::string reason;
      (void)mapper.map(report, g, reason);
    }
    rest = rest.subspan(1 + n);
  }
}
