#pragma once
// Per-frame timing log: <out>/timing.jsonl, one timing record (fovea/xrcommon/timing_record.hpp)
// per line. All times are int64 ns of CLOCK_MONOTONIC (the XrTime base).
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include <glm/vec3.hpp>

#include "fovea/core/clock.hpp"
#include "fovea/xrcommon/timing_writer.hpp"

namespace fovea::runtime {

struct FrameRecord {
  std::int64_t frame = 0;
  core::TimeNs predicted_display_ns = 0;
  core::TimeNs wait_call_ns = 0, wait_return_ns = 0;  // xrWaitFrame entry and return
  core::TimeNs wake_ns = 0;                            // the pacer's wake time for the frame
  core::TimeNs late_ns = 0;                            // wait return past the frame's wake time
  std::int64_t missed_vsyncs = 0;  // vsyncs skipped: xrWaitFrame came late, or the frame missed its vsync
  core::TimeNs begin_ns = 0;                           // xrBeginFrame
  core::TimeNs end_call_ns = 0, end_return_ns = 0;     // xrEndFrame entry and return
  core::TimeNs displayed_ns = 0;  // the vsync that shows the frame (>= submission + compositor budget)
  std::array<xrcommon::PhotonTimes, 2> photon{};  // light from the panel (display model), left and right
  double compositor_ms = 0;                            // read-back, resampling, mask, PNG
  bool composited = false;                             // panel images produced for this frame
  std::uint32_t layers = 0;
  // The newest eye-tracker sample delivered by the frame's read time (xrEndFrame: now, or
  // in lockstep the frame's wake time): when it was measured, received by the host, and the
  // read time (0: none measured yet). gaze_dir: the gaze it gives for the predicted display
  // time (predicted there when the source predicts), the fovea of the record.
  core::TimeNs gaze_sample_ns = 0, gaze_receive_ns = 0, gaze_read_ns = 0;
  bool gaze_valid = false;
  glm::dvec3 gaze_dir{0, 0, -1};
  // The true gaze at the left eye's mid-row photon time (synthetic or recorded source).
  std::optional<glm::dvec3> true_gaze_dir;
  // The head pose of the frame's views: when the application located them (xrLocateViews
  // for this display time; the runtime's read time then) and the time they were predicted
  // for (0: never located).
  core::TimeNs head_pose_ns = 0, head_pose_target_ns = 0;
  // Host time of xrEndFrame's stages (ms, monotonic clock): layer validation, the gaze read,
  // and the compositor's stages (0 on frames it does not produce).
  double cpu_validate_ms = 0, cpu_gaze_ms = 0;
  double cpu_readback_ms = 0, cpu_resample_ms = 0, cpu_lens_ms = 0, cpu_write_ms = 0;
};

class TimingLog {
 public:
  // Starts <dir>/timing.jsonl (truncating); an empty dir disables the log. A file that
  // cannot be opened or written is reported (error log naming it), never silently dropped.
  void open(const std::string& dir);
  void write(const FrameRecord& r);

 private:
  xrcommon::TimingWriter writer_;
};

}  // namespace fovea::runtime
