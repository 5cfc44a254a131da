// Device-backed streams: hid:, usb:, hid-capture:. The mirror window's `mouse` and the
// OpenXR layer's `openxr` sources live in those modules.
#include "fovea/core/error.hpp"
#include "source_uri.hpp"

namespace fovea::devices {

std::unique_ptr<SampleStream> open_device_stream(SourceUri& u, const SourceOptions&) {
  if (u.scheme == "mouse" || u.scheme == "openxr")
    throw core::InputError("gaze source \"" + u.text + "\": provided by the " +
                           (u.scheme == "mouse" ? "mirror window" : "OpenXR layer") + ", not by the devices module");
  throw core::InputError("gaze source \"" + u.text + "\": scheme " + u.scheme + ": not available in this build");
}

}  // namespace fovea::devices
