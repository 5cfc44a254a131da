#pragma once
// An emulated page-0x12 eye tracker: the device side of the protocol, driven by any gaze
// stream. Two descriptor layouts ship: "ms" follows Microsoft's reference eye tracker
// (report IDs 0x10–0x14, 64-bit µs timestamp, int32 µm positions, constant-flagged data
// items); "compact" lays the same usages out differently (report IDs 0x21–0x24, 16-bit
// fields, 10 µs / 0.1 mm / 1 mm unit exponents, vendor items interleaved, push/pop,
// usage ranges, an extended usage, Y before X). The emulated transport can inject faults,
// which is how the transports' error paths are tested at the byte level.
#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string_view>
#include <thread>

#include "fovea/core/view.hpp"
#include "fovea/devices/gaze.hpp"
#include "fovea/devices/hid_eye_tracker.hpp"
#include "fovea/devices/hid_transport.hpp"

namespace fovea::devices::hid {

std::vector<std::uint8_t> reference_descriptor(std::string_view layout);  // "ms" | "compact"

class EmulatedEyeTracker {
 public:
  EmulatedEyeTracker(std::vector<std::uint8_t> descriptor, const DeviceConfig& cfg, const core::View& screen);
  const EyeTrackerCodec& codec() const { return codec_; }
  const DeviceConfig& config() const { return cfg_; }
  std::vector<std::uint8_t> get_feature(std::uint8_t id) const;  // empty: no such report
  bool set_feature(std::span<const std::uint8_t> report);        // false: rejected
  std::uint8_t mode() const { return mode_; }
  // The tracking-data report for a gaze sample (device time = sample time).
  std::vector<std::uint8_t> input_report(const GazeSample& s) const;

 private:
  EyeTrackerCodec codec_;
  DeviceConfig cfg_;
  core::View screen_;
  std::uint8_t mode_ = 0;
};

// Faults injected by the emulated transport, counted in reports read. From a URI:
// hid-emulated:LAYOUT?realtime=1&garbage_every=N&short_every=N&stall_every=N&stall_ms=M&
// unplug_after=N&feature_stall=1&fault_seed=S (docs/hid.md).
struct Faults {
  int garbage_every = 0;       // every Nth read returns random bytes
  int short_every = 0;         // every Nth read returns a truncated report
  int stall_every = 0;         // every Nth read throws a (recoverable) TransportError
  int unplug_after = -1;       // after N reads every call throws TransportError(disconnected)
  bool feature_stall = false;  // GET/SET_REPORT fail
  core::TimeNs clock_offset_ns = 1'000'000'000;  // device -> host clock
  double drift_ppm = 50;
  core::TimeNs delay_ns = 2'000'000;             // mean extra transport delay (exponential)
  std::uint64_t seed = 1;
  // Real time: the device emits each report on its own thread when the sample is due on the
  // host monotonic clock, stamped with the real receive time; a stall also silences the
  // device for stall_ns (the reports of that time are lost, as in a full device buffer).
  bool realtime = false;
  core::TimeNs stall_ns = 0;
};

// Plays a gaze stream as the device's input reports. By default host receive times are
// simulated (device time + offset + drift + random delay), so it runs as fast as it is
// read; with Faults::realtime a device thread paces the reports on the host clock.
class EmulatedTransport final : public Transport {
 public:
  EmulatedTransport(std::unique_ptr<SampleStream> gaze, std::string_view layout, const core::View& screen,
                    const Faults& faults = {});
  ~EmulatedTransport() override;
  DeviceInfo info() const override;
  std::vector<std::uint8_t> report_descriptor() override;
  InputReport read_input(std::span<std::uint8_t> buf, int timeout_ms) override;
  std::vector<std::uint8_t> get_feature(std::uint8_t id, std::size_t length) override;
  void set_feature(std::span<const std::uint8_t> report) override;
  bool exhausted() const override { return exhausted_; }
  core::TimeNs now() const override;
  const EmulatedEyeTracker& device() const { return device_; }
  std::uint64_t reads() const { return reads_; }

 private:
  struct Pending {
    std::vector<std::uint8_t> bytes;
    bool gaze = false;  // a tracking-data report (else the status report)
    core::TimeNs device_ns = 0, host_ns = 0;
  };
  // The device's next report (the status report first, then one per gaze sample); false
  // when the gaze stream has ended.
  bool produce(Pending& out);
  void device_thread();  // realtime: produce() when due, queue with the receive time
  std::unique_ptr<SampleStream> gaze_;
  EmulatedEyeTracker device_;
  Faults faults_;
  std::string layout_;
  std::uint64_t reads_ = 0, rng_;
  core::TimeNs last_host_ = 0;
  bool status_sent_ = false;
  std::atomic<bool> exhausted_{false}, enabled_{false}, stop_{false};
  // Realtime only.
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<Pending> queue_;
  bool produced_all_ = false;
  core::TimeNs silent_until_ = 0;
  std::thread thread_;
};

}  // namespace fovea::devices::hid
