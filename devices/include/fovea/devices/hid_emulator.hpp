#pragma once
// An emulated page-0x12 eye tracker: the device side of the protocol, driven by any gaze
// stream. Two descriptor layouts ship: "ms" follows Microsoft's reference eye tracker
// (report IDs 0x10–0x14, 64-bit µs timestamp, int32 µm positions, constant-flagged data
// items); "compact" lays the same usages out differently (report IDs 0x21–0x24, 16-bit
// fields, 10 µs / 0.1 mm / 1 mm unit exponents, vendor items interleaved, push/pop,
// usage ranges, an extended usage, Y before X). The emulated transport can inject faults,
// which is how the transports' error paths are tested at the byte level.
#include <deque>
#include <functional>
#include <memory>
#include <string_view>

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

// Faults injected by the emulated transport, counted in samples read.
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
};

// Plays a gaze stream as the device's input reports; host receive times are simulated
// (device time + offset + drift + random delay), so it runs as fast as it is read.
class EmulatedTransport final : public Transport {
 public:
  EmulatedTransport(std::unique_ptr<SampleStream> gaze, std::string_view layout, const core::View& screen,
                    const Faults& faults = {});
  DeviceInfo info() const override;
  std::vector<std::uint8_t> report_descriptor() override;
  InputReport read_input(std::span<std::uint8_t> buf, int timeout_ms) override;
  std::vector<std::uint8_t> get_feature(std::uint8_t id, std::size_t length) override;
  void set_feature(std::span<const std::uint8_t> report) override;
  bool exhausted() const override { return exhausted_; }
  core::TimeNs now() const override { return last_host_ + faults_.clock_offset_ns * (last_host_ == 0); }
  const EmulatedEyeTracker& device() const { return device_; }
  std::uint64_t reads() const { return reads_; }

 private:
  std::unique_ptr<SampleStream> gaze_;
  EmulatedEyeTracker device_;
  Faults faults_;
  std::string layout_;
  std::uint64_t reads_ = 0, rng_;
  core::TimeNs last_host_ = 0;
  bool status_sent_ = false, exhausted_ = false;
};

}  // namespace fovea::devices::hid
