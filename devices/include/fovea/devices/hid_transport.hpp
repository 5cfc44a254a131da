#pragma once
// Byte-level access to a HID device, whatever carries it: hidapi (hidraw), libusb
// (interrupt IN endpoint + control transfers) or an emulated device. The gaze stream,
// the start-up handshake and the capture writer sit on top of this interface only.
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "fovea/core/clock.hpp"

namespace fovea::devices::hid {

struct DeviceInfo {
  std::string transport;  // "hidapi", "libusb", "emulated"
  std::string path;       // hidraw node, "usb:BUS-PORTS:IF", ...
  std::uint16_t vendor_id = 0, product_id = 0;
  std::uint16_t usage_page = 0, usage = 0;  // of the top-level collection (0 if unknown)
  int interface_number = -1;
  std::string manufacturer, product, serial;
};

// A transport failure. `disconnected` means the device is gone (unplugged); otherwise the
// operation failed (stall, timeout on a control transfer, I/O error) and may be retried.
class TransportError : public std::runtime_error {
 public:
  TransportError(const std::string& what, bool disconnected) : std::runtime_error(what), disconnected_(disconnected) {}
  bool disconnected() const { return disconnected_; }

 private:
  bool disconnected_;
};

struct InputReport {
  std::size_t size = 0;         // 0: nothing within the timeout
  core::TimeNs host_ns = 0;     // host monotonic receive time
};

class Transport {
 public:
  virtual ~Transport() = default;
  virtual DeviceInfo info() const = 0;
  virtual std::vector<std::uint8_t> report_descriptor() = 0;
  // One input report into `buf` (report ID first when the device uses IDs). Throws TransportError.
  virtual InputReport read_input(std::span<std::uint8_t> buf, int timeout_ms) = 0;
  // GET_REPORT(Feature, id): the report, ID first. Throws TransportError.
  virtual std::vector<std::uint8_t> get_feature(std::uint8_t id, std::size_t length) = 0;
  // SET_REPORT(Feature): `report` starts with the ID. Throws TransportError.
  virtual void set_feature(std::span<const std::uint8_t> report) = 0;
  // The host clock the transport stamps reports with (simulated for an emulated device).
  virtual core::TimeNs now() const { return core::now_ns(); }
  // True once a finite source (an emulated device playing a recording) has nothing more.
  virtual bool exhausted() const { return false; }
};

// Enumeration of page-0x12 devices by each transport (empty if the transport is not
// usable on this system; `error` then says why).
struct Enumeration {
  std::vector<DeviceInfo> devices;
  std::string error;
};
Enumeration enumerate_hidapi();
Enumeration enumerate_libusb();

// Open by "VID:PID" (hex), by path, or "" for the first eye tracker found. Throws core::InputError.
std::unique_ptr<Transport> open_hidapi(const std::string& selector);
std::unique_ptr<Transport> open_libusb(const std::string& selector);

}  // namespace fovea::devices::hid
