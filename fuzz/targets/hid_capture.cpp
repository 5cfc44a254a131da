// HID captures (hid-capture:FILE): header, descriptor, feature and input report lines,
// replayed through the eye-tracker codec and the gaze mapper.
#include "../harness.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "../gaze_options.hpp"

FOVEA_FUZZ_TARGET(hid_capture) {
  fovea::devices::hid::HidCaptureStream s(fovea::fuzz::scratch_file("fuzz.hidcap", fovea::fuzz::as_text(data)),
                                          fovea::fuzz::gaze_options());
  fovea::devices::GazeSample g;
  while (s.next(g)) {
  }
}
