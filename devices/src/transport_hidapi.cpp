// hidapi (hidraw backend) transport. The report descriptor comes from sysfs
// (/sys/class/hidraw/hidrawN/device/report_descriptor): hidapi 0.13 has no call for it.
#include <hidapi/hidapi.h>
#include <unistd.h>

#include <cstdio>
#include <cwchar>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>

#include "fovea/core/error.hpp"
#include "fovea/devices/hid_eye_tracker.hpp"
#include "transport_errors.hpp"

namespace fovea::devices::hid {

namespace detail {

TransportError hidapi_failure(const std::string& path, const std::string& message, bool node_exists) {
  return TransportError(path + ": " + message, !node_exists);
}

bool parse_vid_pid(const std::string& s, std::uint16_t& vid, std::uint16_t& pid) {
  unsigned v = 0, p = 0;
  char tail = 0;
  if (std::sscanf(s.c_str(), "%x:%x%c", &v, &p, &tail) != 2 || v > 0xFFFF || p > 0xFFFF) return false;
  vid = static_cast<std::uint16_t>(v);
  pid = static_cast<std::uint16_t>(p);
  return true;
}

}  // namespace detail

namespace {

std::string narrow(const wchar_t* w) {
  std::string s;
  if (!w) return s;
  for (; *w; ++w) s += (*w < 128) ? static_cast<char>(*w) : '?';
  return s;
}

bool hid_ready(std::string& error) {
  static std::once_flag once;
  static int rc = 0;
  std::call_once(once, [] { rc = hid_init(); });
  if (rc != 0) error = "hid_init failed";
  return rc == 0;
}

DeviceInfo to_info(const hid_device_info* d) {
  DeviceInfo i;
  i.transport = "hidapi";
  i.path = d->path ? d->path : "";
  i.vendor_id = d->vendor_id;
  i.product_id = d->product_id;
  i.usage_page = d->usage_page;
  i.usage = d->usage;
  i.interface_number = d->interface_number;
  i.manufacturer = narrow(d->manufacturer_string);
  i.product = narrow(d->product_string);
  i.serial = narrow(d->serial_number);
  return i;
}

class HidapiTransport final : public Transport {
 public:
  HidapiTransport(hid_device* dev, DeviceInfo info) : dev_(dev), info_(std::move(info)) {}
  ~HidapiTransport() override { hid_close(dev_); }
  DeviceInfo info() const override { return info_; }

  std::vector<std::uint8_t> report_descriptor() override {
    const std::string node = std::filesystem::path(info_.path).filename().string();
    std::ifstream f("/sys/class/hidraw/" + node + "/device/report_descriptor", std::ios::binary);
    if (!f) throw TransportError(info_.path + ": cannot read the report descriptor from sysfs", false);
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(f), {});
  }

  InputReport read_input(std::span<std::uint8_t> buf, int timeout_ms) override {
    const int n = hid_read_timeout(dev_, buf.data(), buf.size(), timeout_ms);
    const core::TimeNs t = core::now_ns();
    if (n < 0) throw failure("read failed");
    return {static_cast<std::size_t>(n), t};
  }

  std::vector<std::uint8_t> get_feature(std::uint8_t id, std::size_t length) override {
    std::vector<std::uint8_t> r(std::max<std::size_t>(length, 1) + 1, 0);
    r[0] = id;
    const int n = hid_get_feature_report(dev_, r.data(), r.size());
    if (n < 0) throw failure("GET_REPORT(feature " + std::to_string(id) + ") failed");
    r.resize(static_cast<std::size_t>(n));
    return r;
  }

  void set_feature(std::span<const std::uint8_t> report) override {
    if (hid_send_feature_report(dev_, report.data(), report.size()) < 0) throw failure("SET_REPORT(feature) failed");
  }

 private:
  TransportError failure(const std::string& what) {
    return detail::hidapi_failure(info_.path, what + ": " + narrow(hid_error(dev_)), ::access(info_.path.c_str(), F_OK) == 0);
  }
  hid_device* dev_;
  DeviceInfo info_;
};

}  // namespace

Enumeration enumerate_hidapi() {
  Enumeration e;
  if (!hid_ready(e.error)) return e;
  hid_device_info* list = hid_enumerate(0, 0);
  for (hid_device_info* d = list; d; d = d->next)
    if (d->usage_page == kEyeTrackerPage) e.devices.push_back(to_info(d));
  hid_free_enumeration(list);
  return e;
}

std::unique_ptr<Transport> open_hidapi(const std::string& selector) {
  std::string error;
  if (!hid_ready(error)) throw core::InputError("hid: " + error);
  std::uint16_t vid = 0, pid = 0;
  const bool by_id = detail::parse_vid_pid(selector, vid, pid);
  if (!selector.empty() && !by_id && selector.find('/') == std::string::npos)
    throw core::InputError("hid:" + selector + ": expected VID:PID (hex) or a hidraw path");
  hid_device_info* list = hid_enumerate(by_id ? vid : 0, by_id ? pid : 0);
  DeviceInfo chosen;
  bool found = false;
  for (hid_device_info* d = list; d && !found; d = d->next) {
    const bool match = (selector.empty() || by_id) ? d->usage_page == kEyeTrackerPage : selector == (d->path ? d->path : "");
    if (match) {
      chosen = to_info(d);
      found = true;
    }
  }
  hid_free_enumeration(list);
  if (!found) throw core::InputError("hid:" + selector + ": no HID eye tracker (usage page 0x12) found");
  hid_device* dev = hid_open_path(chosen.path.c_str());
  if (!dev) throw core::InputError("hid:" + selector + ": cannot open " + chosen.path + " (permissions?)");
  return std::make_unique<HidapiTransport>(dev, chosen);
}

}  // namespace fovea::devices::hid
