#pragma once
// How the transports turn library status codes into TransportError (kept apart from the
// library calls so the mapping is testable without a device).
#include <string>

#include "fovea/devices/hid_transport.hpp"

namespace fovea::devices::hid::detail {

// libusb status -> error; `rc` is a libusb_error value (negative).
TransportError libusb_failure(int rc, const std::string& what);
// hidapi reports -1 and a message; the device is gone if its node disappeared.
TransportError hidapi_failure(const std::string& path, const std::string& message, bool node_exists);
// "VID:PID" in hex -> ids; false if malformed.
bool parse_vid_pid(const std::string& s, std::uint16_t& vid, std::uint16_t& pid);

}  // namespace fovea::devices::hid::detail
