// fovea devices: eye trackers (HID usage page 0x12) found by hidapi and by libusb.
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fovea/devices/hid_transport.hpp"

namespace fovea::tools::cmd_devices {

namespace {

int run(std::vector<std::string> args) {
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      std::cout << "usage: fovea devices [--json]\n"
                   "Lists HID eye trackers (usage page 0x12) found through hidapi (hidraw) and libusb:\n"
                   "VID:PID, path, usage page, manufacturer and product strings. Open one with\n"
                   "--gaze hid:VID:PID or usb:VID:PID (docs/hid.md).\n";
      return 0;
    }
  Args a(args, {}, {"json"}, 0);
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [name, e] : {std::pair{"hidapi", devices::hid::enumerate_hidapi()}, std::pair{"libusb", devices::hid::enumerate_libusb()}}) {
    if (!e.error.empty() && !a.has("json")) std::cerr << name << ": " << e.error << "\n";
    for (const auto& d : e.devices) {
      char id[16];
      std::snprintf(id, sizeof id, "%04x:%04x", d.vendor_id, d.product_id);
      out.push_back({{"transport", d.transport}, {"id", id}, {"path", d.path}, {"usage_page", d.usage_page},
                     {"usage", d.usage}, {"interface", d.interface_number}, {"manufacturer", d.manufacturer},
                     {"product", d.product}, {"serial", d.serial}});
      if (!a.has("json"))
        std::cout << name << "  " << id << "  " << d.path << "  page 0x" << std::hex << d.usage_page << std::dec << "  "
                  << d.manufacturer << " " << d.product << "\n";
    }
  }
  if (a.has("json")) std::cout << out.dump(2) << "\n";
  else if (out.empty()) std::cout << "no HID eye trackers found\n";
  return 0;
}

}  // namespace

FOVEA_COMMAND(devices_cmd, "devices", "list HID eye trackers (usage page 0x12) via hidapi and libusb", run);

}  // namespace fovea::tools::cmd_devices
