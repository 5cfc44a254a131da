// Device-backed streams: hid:, usb:, hid-capture:, hid-emulated:. The mirror window's
// `mouse` and the OpenXR layer's `openxr` sources live in those modules.
#include <cmath>

#include "fovea/core/error.hpp"
#include "fovea/devices/hid_emulator.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "fovea/devices/synthetic.hpp"
#include "source_uri.hpp"

namespace fovea::devices {

std::unique_ptr<SampleStream> open_device_stream(SourceUri& u, const SourceOptions& opt) {
  if (u.scheme == "mouse" || u.scheme == "openxr")
    throw core::InputError("gaze source \"" + u.text + "\": provided by the " +
                           (u.scheme == "mouse" ? "mirror window" : "OpenXR layer") + ", not by the devices module");
  if (u.scheme == "hid-capture") {
    SourceOptions timeline = opt;
    take_timeline_keys(u, timeline);  // checked; walking every sample does not use them
    u.finish();
    if (!opt.raw_capture.empty()) throw core::InputError("gaze source \"" + u.text + "\": a capture replay cannot be captured again");
    return std::make_unique<hid::HidCaptureStream>(u.body, opt);
  }
  if (u.scheme == "hid-emulated") {
    // An emulated page-0x12 device playing synthetic gaze: hid-emulated:LAYOUT?seed=&task=&rate=&seconds=
    SynthParams p;
    p.seed = static_cast<std::uint64_t>(u.take_number("seed", 1, 0, 9e15));
    if (auto t = u.take("task"); !t.empty()) p.task = parse_synth_task(t);
    p.rate_hz = u.take_number("rate", p.rate_hz, 60, 1000);
    p.seconds = u.take_seconds(0);
    p.ipd_m = opt.display.ipd_m;
    // Faults and pacing, so a layer or runtime can be tested against a live-timed device
    // that misbehaves (counts are in reports read by the host).
    hid::Faults f;
    auto flag = [&](const char* key) {
      const std::string v = u.take(key);
      if (!v.empty() && v != "0" && v != "1")
        throw core::InputError("gaze source \"" + u.text + "\": " + key + " must be 0 or 1");
      return v == "1";
    };
    f.realtime = flag("realtime");
    f.feature_stall = flag("feature_stall");
    f.garbage_every = static_cast<int>(u.take_number("garbage_every", 0, 0, 1e9));
    f.short_every = static_cast<int>(u.take_number("short_every", 0, 0, 1e9));
    f.stall_every = static_cast<int>(u.take_number("stall_every", 0, 0, 1e9));
    f.stall_ns = std::llround(u.take_number("stall_ms", 0, 0, 60000) * 1e6);
    f.unplug_after = static_cast<int>(u.take_number("unplug_after", -1, -1, 1e9));
    f.seed = static_cast<std::uint64_t>(u.take_number("fault_seed", 1, 0, 9e15));
    u.finish();
    auto t = std::make_unique<hid::EmulatedTransport>(std::make_unique<SyntheticStream>(p), u.body.empty() ? "ms" : u.body,
                                                      opt.screen_view(), f);
    return std::make_unique<hid::HidGazeStream>(std::move(t), opt, opt.raw_capture);
  }
  if (u.scheme == "hid" || u.scheme == "usb") {
    u.finish();
    auto t = u.scheme == "hid" ? hid::open_hidapi(u.body) : hid::open_libusb(u.body);
    return std::make_unique<hid::HidGazeStream>(std::move(t), opt, opt.raw_capture);
  }
  throw core::InputError("gaze source \"" + u.text + "\": unknown scheme " + u.scheme);
}

}  // namespace fovea::devices
