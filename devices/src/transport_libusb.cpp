// libusb transport: claims the HID interface, reads the interrupt IN endpoint, and uses
// class requests on the control endpoint (GET_DESCRIPTOR(Report), GET_REPORT/SET_REPORT
// for feature reports, HID 1.11 §7.1–7.2). Unplug is noticed through libusb's hot-plug
// callback where the platform supports it, and through LIBUSB_ERROR_NO_DEVICE otherwise.
#include <libusb.h>

#include <atomic>
#include <cstdio>
#include <sys/time.h>

#include "fovea/core/error.hpp"
#include "fovea/devices/hid_descriptor.hpp"
#include "fovea/devices/hid_eye_tracker.hpp"
#include "transport_errors.hpp"

namespace fovea::devices::hid {

namespace detail {
TransportError libusb_failure(int rc, const std::string& what) {
  const bool gone = rc == LIBUSB_ERROR_NO_DEVICE || rc == LIBUSB_ERROR_NOT_FOUND;
  return TransportError(what + ": " + libusb_error_name(rc), gone);
}
}  // namespace detail

namespace {

// bmRequestType: direction | type | recipient (USB 2.0 §9.3.1).
constexpr std::uint8_t kInStandardInterface = 0x81, kInClassInterface = 0xA1, kOutClassInterface = 0x21;
constexpr std::uint8_t kGetReport = 0x01, kSetReport = 0x09, kReportTypeFeature = 3, kDescriptorReport = 0x22;

struct HidInterface {
  int number = -1;
  std::uint8_t in_endpoint = 0;
  std::uint16_t in_packet = 64;
  std::uint16_t report_length = 0;  // from the class (HID) descriptor
};

// HID interfaces of a device with their interrupt IN endpoints.
std::vector<HidInterface> hid_interfaces(libusb_device* dev) {
  std::vector<HidInterface> out;
  libusb_config_descriptor* cfg = nullptr;
  if (libusb_get_active_config_descriptor(dev, &cfg) != 0 || !cfg) return out;
  for (int i = 0; i < cfg->bNumInterfaces; ++i) {
    const libusb_interface& itf = cfg->interface[i];
    if (itf.num_altsetting < 1) continue;
    const libusb_interface_descriptor& alt = itf.altsetting[0];
    if (alt.bInterfaceClass != LIBUSB_CLASS_HID) continue;
    HidInterface h;
    h.number = alt.bInterfaceNumber;
    for (int e = 0; e < alt.bNumEndpoints; ++e) {
      const libusb_endpoint_descriptor& ep = alt.endpoint[e];
      if ((ep.bEndpointAddress & LIBUSB_ENDPOINT_IN) && (ep.bmAttributes & 3) == LIBUSB_TRANSFER_TYPE_INTERRUPT) {
        h.in_endpoint = ep.bEndpointAddress;
        h.in_packet = ep.wMaxPacketSize;
      }
    }
    // HID class descriptor (type 0x21) in the interface's extra bytes: wDescriptorLength at 7.
    const unsigned char* x = alt.extra;
    for (int k = 0; x && k + 9 <= alt.extra_length; k += x[k] ? x[k] : alt.extra_length)
      if (x[k + 1] == 0x21 && x[k + 6] == kDescriptorReport) h.report_length = static_cast<std::uint16_t>(x[k + 7] | x[k + 8] << 8);
    if (h.in_endpoint) out.push_back(h);
  }
  libusb_free_config_descriptor(cfg);
  return out;
}

std::vector<std::uint8_t> read_report_descriptor(libusb_device_handle* h, const HidInterface& itf) {
  std::vector<std::uint8_t> d(itf.report_length ? itf.report_length : 4096);
  const int n = libusb_control_transfer(h, kInStandardInterface,
                                        LIBUSB_REQUEST_GET_DESCRIPTOR, kDescriptorReport << 8,
                                        static_cast<std::uint16_t>(itf.number), d.data(), static_cast<std::uint16_t>(d.size()), 1000);
  if (n < 0) throw detail::libusb_failure(n, "GET_DESCRIPTOR(Report)");
  d.resize(static_cast<std::size_t>(n));
  return d;
}

// The top-level collection's usage page: the first Usage Page item before any collection.
std::uint16_t top_usage_page(const std::vector<std::uint8_t>& d) {
  try {
    const Descriptor parsed = parse_descriptor(d);
    for (const Field& f : parsed.fields)
      if (!f.collections.empty()) return static_cast<std::uint16_t>(f.collections.front() >> 16);
  } catch (const core::InputError&) {
  }
  return 0;
}

std::string string_descriptor(libusb_device_handle* h, std::uint8_t index) {
  if (!index) return {};
  unsigned char buf[256];
  const int n = libusb_get_string_descriptor_ascii(h, index, buf, sizeof buf);
  return n > 0 ? std::string(reinterpret_cast<char*>(buf), static_cast<std::size_t>(n)) : std::string();
}

std::string usb_path(libusb_device* dev, int itf) {
  std::uint8_t ports[8];
  const int n = libusb_get_port_numbers(dev, ports, 8);
  std::string p = "usb:" + std::to_string(libusb_get_bus_number(dev)) + "-";
  for (int i = 0; i < n; ++i) p += (i ? "." : "") + std::to_string(ports[i]);
  return p + ":" + std::to_string(itf);
}

struct Context {
  libusb_context* ctx = nullptr;
  int rc = 0;
  Context() { rc = libusb_init(&ctx); }
  ~Context() {
    if (ctx) libusb_exit(ctx);
  }
};

class LibusbTransport final : public Transport {
 public:
  LibusbTransport(std::unique_ptr<Context> c, libusb_device_handle* h, HidInterface itf, DeviceInfo info)
      : ctx_(std::move(c)), h_(h), itf_(itf), info_(std::move(info)) {
    if (libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG)) {
      libusb_hotplug_register_callback(ctx_->ctx, LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT, LIBUSB_HOTPLUG_NO_FLAGS, info_.vendor_id,
                                       info_.product_id, LIBUSB_HOTPLUG_MATCH_ANY, &LibusbTransport::on_hotplug, this, &hotplug_);
    }
  }
  ~LibusbTransport() override {
    if (hotplug_) libusb_hotplug_deregister_callback(ctx_->ctx, hotplug_);
    libusb_release_interface(h_, itf_.number);
    libusb_close(h_);
  }
  DeviceInfo info() const override { return info_; }
  std::vector<std::uint8_t> report_descriptor() override { return read_report_descriptor(h_, itf_); }

  InputReport read_input(std::span<std::uint8_t> buf, int timeout_ms) override {
    timeval zero{0, 0};
    libusb_handle_events_timeout_completed(ctx_->ctx, &zero, nullptr);  // delivers hot-plug events
    if (gone_) throw TransportError(info_.path + ": device left (hot-plug)", true);
    int got = 0;
    const int rc = libusb_interrupt_transfer(h_, itf_.in_endpoint, buf.data(), static_cast<int>(buf.size()), &got, timeout_ms);
    const core::TimeNs t = core::now_ns();
    if (rc == LIBUSB_ERROR_TIMEOUT) return {static_cast<std::size_t>(got), t};
    if (rc == LIBUSB_ERROR_PIPE) libusb_clear_halt(h_, itf_.in_endpoint);  // a stall: clear and report
    if (rc != 0) throw detail::libusb_failure(rc, info_.path + ": interrupt IN");
    return {static_cast<std::size_t>(got), t};
  }

  std::vector<std::uint8_t> get_feature(std::uint8_t id, std::size_t length) override {
    std::vector<std::uint8_t> r(std::max<std::size_t>(length, 1));
    const int n = libusb_control_transfer(h_, kInClassInterface,
                                          kGetReport, static_cast<std::uint16_t>(kReportTypeFeature << 8 | id),
                                          static_cast<std::uint16_t>(itf_.number), r.data(), static_cast<std::uint16_t>(r.size()), 1000);
    if (n < 0) throw detail::libusb_failure(n, info_.path + ": GET_REPORT(feature " + std::to_string(id) + ")");
    r.resize(static_cast<std::size_t>(n));
    return r;
  }

  void set_feature(std::span<const std::uint8_t> report) override {
    if (report.empty()) return;
    std::vector<std::uint8_t> r(report.begin(), report.end());
    const int n = libusb_control_transfer(h_, kOutClassInterface,
                                          kSetReport, static_cast<std::uint16_t>(kReportTypeFeature << 8 | r[0]),
                                          static_cast<std::uint16_t>(itf_.number), r.data(), static_cast<std::uint16_t>(r.size()), 1000);
    if (n < 0) throw detail::libusb_failure(n, info_.path + ": SET_REPORT(feature)");
  }

 private:
  static int on_hotplug(libusb_context*, libusb_device*, libusb_hotplug_event, void* self) {
    static_cast<LibusbTransport*>(self)->gone_ = true;
    return 0;
  }
  std::unique_ptr<Context> ctx_;
  libusb_device_handle* h_;
  HidInterface itf_;
  DeviceInfo info_;
  libusb_hotplug_callback_handle hotplug_ = 0;
  std::atomic<bool> gone_{false};
};

// Visits every HID interface that is a page-0x12 eye tracker. Devices that cannot be
// opened (permissions, in use) are counted in `skipped`.
template <class Fn>
void for_each_tracker(libusb_context* ctx, int& skipped, Fn&& fn) {
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(ctx, &list);
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device* dev = list[i];
    const auto itfs = hid_interfaces(dev);
    if (itfs.empty()) continue;
    libusb_device_handle* h = nullptr;
    if (libusb_open(dev, &h) != 0) {
      ++skipped;
      continue;
    }
    libusb_device_descriptor dd{};
    libusb_get_device_descriptor(dev, &dd);
    bool keep = false;
    for (const HidInterface& itf : itfs) {
      std::vector<std::uint8_t> desc;
      try {
        desc = read_report_descriptor(h, itf);
      } catch (const TransportError&) {
        ++skipped;
        continue;
      }
      if (top_usage_page(desc) != kEyeTrackerPage) continue;
      DeviceInfo info;
      info.transport = "libusb";
      info.path = usb_path(dev, itf.number);
      info.vendor_id = dd.idVendor;
      info.product_id = dd.idProduct;
      info.usage_page = kEyeTrackerPage;
      info.usage = usage::kEyeTracker;
      info.interface_number = itf.number;
      info.manufacturer = string_descriptor(h, dd.iManufacturer);
      info.product = string_descriptor(h, dd.iProduct);
      info.serial = string_descriptor(h, dd.iSerialNumber);
      if (fn(h, itf, info)) {
        keep = true;
        break;
      }
    }
    if (!keep) libusb_close(h);
    else break;
  }
  if (n >= 0) libusb_free_device_list(list, 1);
}

}  // namespace

Enumeration enumerate_libusb() {
  Enumeration e;
  Context c;
  if (c.rc != 0) {
    e.error = std::string("libusb_init: ") + libusb_error_name(c.rc);
    return e;
  }
  int skipped = 0;
  for_each_tracker(c.ctx, skipped, [&](libusb_device_handle*, const HidInterface&, const DeviceInfo& info) {
    e.devices.push_back(info);
    return false;
  });
  if (skipped) e.error = std::to_string(skipped) + " HID interface(s) could not be opened or read (permissions?)";
  return e;
}

std::unique_ptr<Transport> open_libusb(const std::string& selector) {
  std::uint16_t vid = 0, pid = 0;
  const bool by_id = detail::parse_vid_pid(selector, vid, pid);
  if (!selector.empty() && !by_id) throw core::InputError("usb:" + selector + ": expected VID:PID (hex)");
  auto c = std::make_unique<Context>();
  if (c->rc != 0) throw core::InputError(std::string("usb: libusb_init: ") + libusb_error_name(c->rc));
  int skipped = 0;
  libusb_device_handle* handle = nullptr;
  HidInterface chosen;
  DeviceInfo info;
  for_each_tracker(c->ctx, skipped, [&](libusb_device_handle* h, const HidInterface& itf, const DeviceInfo& i) {
    if (by_id && (i.vendor_id != vid || i.product_id != pid)) return false;
    handle = h;
    chosen = itf;
    info = i;
    return true;
  });
  if (!handle)
    throw core::InputError("usb:" + selector + ": no HID eye tracker (usage page 0x12) found" +
                           (skipped ? " (" + std::to_string(skipped) + " HID interface(s) not accessible)" : std::string()));
  libusb_set_auto_detach_kernel_driver(handle, 1);
  const int rc = libusb_claim_interface(handle, chosen.number);
  if (rc != 0) {
    libusb_close(handle);
    throw core::InputError("usb:" + selector + ": cannot claim interface " + std::to_string(chosen.number) + ": " + libusb_error_name(rc));
  }
  return std::make_unique<LibusbTransport>(std::move(c), handle, chosen, info);
}

}  // namespace fovea::devices::hid
