#pragma once
// Per-frame timing log: one JSON object per line in <out>/timing.jsonl. All times are int64
// ns of CLOCK_MONOTONIC (the XrTime base).
#include <cstdint>
#include <cstdio>
#include <string>

#include "fovea/core/clock.hpp"

namespace fovea::runtime {

struct FrameRecord {
  std::int64_t frame = 0;
  core::TimeNs predicted_display_ns = 0;
  core::TimeNs wait_call_ns = 0, wait_return_ns = 0;  // xrWaitFrame entry and return
  core::TimeNs late_ns = 0;                            // wait return past the frame's wake time
  std::int64_t missed_vsyncs = 0;                      // vsyncs skipped because xrWaitFrame came late
  core::TimeNs begin_ns = 0;                           // xrBeginFrame
  core::TimeNs end_call_ns = 0, end_return_ns = 0;     // xrEndFrame entry and return
  core::TimeNs displayed_ns = 0;  // the vsync that shows the frame (>= submission + compositor budget)
  double compositor_ms = 0;                            // read-back, resampling, mask, PNG
  bool composited = false;                             // panel images produced for this frame
  std::uint32_t layers = 0;
  // The newest eye-tracker sample used for the predicted display time: when it was
  // measured, received by the host, and read for this frame (0: none measured yet).
  core::TimeNs gaze_sample_ns = 0, gaze_receive_ns = 0, gaze_read_ns = 0;
  bool gaze_valid = false;
  // Host time of xrEndFrame's stages (ms, monotonic clock): layer validation, the gaze read,
  // and the compositor's stages (0 on frames it does not produce).
  double cpu_validate_ms = 0, cpu_gaze_ms = 0;
  double cpu_readback_ms = 0, cpu_resample_ms = 0, cpu_lens_ms = 0, cpu_write_ms = 0;
};

class TimingLog {
 public:
  TimingLog() = default;
  ~TimingLog();
  TimingLog(const TimingLog&) = delete;
  TimingLog& operator=(const TimingLog&) = delete;
  // Starts <dir>/timing.jsonl (truncating); an empty dir disables the log. A file that
  // cannot be opened or written is reported (error log naming it), never silently dropped.
  void open(const std::string& dir);
  void write(const FrameRecord& r);

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
};

}  // namespace fovea::runtime
