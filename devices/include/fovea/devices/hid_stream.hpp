#pragma once
// Gaze from HID eye trackers: the live stream over any Transport (start-up handshake,
// reader thread, clock-offset estimation, optional raw capture) and the replay of raw
// captures through the same decoder. Capture format: docs/hid.md.
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "fovea/devices/clock_sync.hpp"
#include "fovea/devices/gaze.hpp"
#include "fovea/devices/hid_eye_tracker.hpp"
#include "fovea/devices/hid_transport.hpp"
#include "fovea/devices/readers.hpp"

namespace fovea::devices::hid {

// Report bytes -> GazeSample: unwraps the sensor timestamp, maps the gaze point (metres on
// the calibrated screen, top-left, y down) through the screen view to a view direction.
// Per-eye gaze equals the combined gaze (the page carries eye positions, not eye directions).
class GazeMapper {
 public:
  GazeMapper(const EyeTrackerCodec& codec, const core::View& screen) : codec_(codec), screen_(screen) {}
  bool map(std::span<const std::uint8_t> report, GazeSample& out, std::string& reason);
  void feature(std::span<const std::uint8_t> report) { codec_.decode_feature(report, cfg_); }
  const DeviceConfig& config() const { return cfg_; }
  void reset() {
    cfg_ = DeviceConfig{};
    have_last_ = false;
    wraps_ = 0;
  }

 private:
  const EyeTrackerCodec& codec_;
  core::View screen_;
  DeviceConfig cfg_;
  bool have_last_ = false;
  std::int64_t last_raw_ = 0, wraps_ = 0;
  core::TimeNs last_device_ = 0;
};

// Text capture of raw device traffic, written atomically on finish().
class CaptureWriter {
 public:
  CaptureWriter(const std::string& path, const DeviceInfo& info, std::span<const std::uint8_t> descriptor);
  ~CaptureWriter();
  void get_feature(core::TimeNs host_ns, std::span<const std::uint8_t> report);
  void set_feature(core::TimeNs host_ns, std::span<const std::uint8_t> report);
  void input(core::TimeNs host_ns, std::span<const std::uint8_t> report);
  void finish();

 private:
  void line(const char* kind, core::TimeNs t, std::span<const std::uint8_t> r);
  std::string path_, tmp_;
  std::FILE* f_ = nullptr;
};

struct StreamStats {
  std::uint64_t reports = 0, samples = 0, status_reports = 0, transport_errors = 0;
  std::map<std::string, std::uint64_t> dropped;  // reports discarded, by reason
  std::vector<std::string> notes;                 // start-up problems survived
  bool disconnected = false;
  double clock_drift_ppm = 0;
};

class HidGazeStream final : public SampleStream {
 public:
  // Runs the start-up handshake synchronously (throws core::InputError if the device is
  // not a usable page-0x12 eye tracker), then reads reports on a thread.
  HidGazeStream(std::unique_ptr<Transport> transport, const SourceOptions& opt, const std::string& capture_path = "");
  ~HidGazeStream() override;
  bool next(GazeSample& out) override;  // non-blocking
  bool live() const override { return true; }
  std::string describe() const override;
  StreamStats stats() const;
  const DeviceConfig& config() const { return config_; }
  // The reader has stopped: device unplugged or a finite (emulated) source exhausted.
  bool finished() const { return finished_; }
  void stop();  // joins the reader and completes the capture file

 private:
  void run();
  std::unique_ptr<Transport> transport_;
  DeviceInfo info_;
  std::unique_ptr<EyeTrackerCodec> codec_;
  std::unique_ptr<GazeMapper> mapper_;
  std::unique_ptr<CaptureWriter> capture_;
  DeviceConfig config_;
  ClockSync clock_;
  mutable std::mutex mutex_;
  std::condition_variable space_;
  std::deque<GazeSample> queue_;
  StreamStats stats_;
  core::TimeNs last_t_ = 0;
  std::atomic<bool> stop_{false}, finished_{false};
  std::thread thread_;
};

// hid-capture:FILE, or a capture file detected as such (plain or gzip) — replays a capture
// through the same codec and mapper, as a reader like the other recorded formats: the same
// notes (truncated gzip, gaze off the screen) and, the page having no blink usage, blinks
// inferred from untracked runs. Timeline: device time from the first sample; host_time_ns:
// the captured receive time.
class HidCaptureStream final : public GazeReader {
 public:
  HidCaptureStream(const std::string& path, const SourceOptions& opt);
  ~HidCaptureStream() override;
  bool next(GazeSample& out) override;
  bool rewindable() const override { return true; }
  void rewind() override;
  std::string describe() const override { return "hid-capture:" + path_; }
  const ReadStats& stats() const override { return stats_; }
  Format format() const override { return Format::HidCapture; }
  bool reports_blinks() const override { return false; }
  std::string metadata_json() const override { return "{}"; }
  core::TimeNs time_origin_ns() const override { return first_; }
  const EyeTrackerCodec& codec() const { return *codec_; }
  const DeviceConfig& config() const { return mapper_->config(); }

 private:
  struct Lines;  // the line reader and the readers' shared notes policy (src/read_notes.hpp)
  std::string path_;
  SourceOptions opt_;
  std::unique_ptr<Lines> lines_;
  std::unique_ptr<EyeTrackerCodec> codec_;
  std::unique_ptr<GazeMapper> mapper_;
  ReadStats stats_;
  bool have_first_ = false, ended_ = false;
  core::TimeNs first_ = 0;
  std::vector<std::uint8_t> buf_;
};

}  // namespace fovea::devices::hid
