#pragma once
// The per-frame timing record every producer writes — the runtime (timing.jsonl), the API
// layer (layer_timing.jsonl), `fovea render` (frame_times.jsonl), `fovea latency`
// (records.jsonl) — and `fovea latency --records` reads: one JSON object per line, schema
// "fovea-timing", version kTimingVersion. Every time is int64 ns on the clock the record
// names ("monotonic": CLOCK_MONOTONIC, which the project's runtime uses for XrTime, another
// runtime need not: the layer converts the runtime's XrTime values where it can and says so in
// its xr_time_converted field; "virtual": a simulation's timeline from 0), except
// gaze_device_ns, on the eye tracker's own clock. Fields and their events:
// docs/openxr.md ("Timing records").
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include <glm/vec3.hpp>

#include "fovea/core/clock.hpp"
#include "fovea/xrcommon/display_model.hpp"

namespace fovea::xrcommon {

inline constexpr int kTimingVersion = 1;

enum class TimeBase { Monotonic, Virtual };

struct TimingRecord {
  std::string source;                  // "runtime", "layer", "render", "latency"
  TimeBase clock = TimeBase::Monotonic;
  std::int64_t frame = 0;
  // The OpenXR session the frame belongs to, numbered in the producer's process from 0 in
  // creation order (absent: not an OpenXR session's record). Several sessions of one process
  // share one file.
  std::optional<std::int64_t> session;
  // The gaze sample the frame used: when it was measured, its stamp on the tracker's clock,
  // when the host received it, and when the renderer read it. Absent: not known / none.
  bool gaze_valid = false;
  std::optional<core::TimeNs> gaze_sample_ns, gaze_device_ns, gaze_receive_ns, gaze_read_ns;
  std::optional<core::TimeNs> head_pose_ns;          // when the head pose the frame was rendered for was sampled
  std::optional<core::TimeNs> head_pose_target_ns;   // the time that pose was predicted for (its display time)
  std::optional<core::TimeNs> predicted_display_ns;  // the display time the frame was rendered for
  // The OpenXR frame loop's calls (absent outside one).
  std::optional<core::TimeNs> wait_call_ns, wait_return_ns, begin_ns, end_call_ns, end_return_ns;
  std::optional<core::TimeNs> submit_ns;  // the frame handed to the compositor / display
  std::optional<core::TimeNs> vsync_ns;   // the vsync whose scan-out shows it
  std::int64_t missed_vsyncs = 0;         // vsyncs it came too late for (the previous frame stayed)
  std::optional<std::array<PhotonTimes, 2>> photon_ns;  // left, right eye
  // Per stage, milliseconds (monotonic clock on the CPU; GPU timestamps).
  std::vector<std::pair<std::string, double>> cpu_ms, gpu_ms;
  // Ground truth, when the producer knows it (synthetic gaze, a replay, a tracker model): the
  // direction the frame was foveated for and the true gaze at its photon time (left eye, mid
  // row), both the combined gaze in view space; foveal_error_deg is the angle between them.
  std::optional<glm::dvec3> fovea_dir, true_gaze_dir;
  // Producer-specific fields, written at the top level after the schema's.
  std::vector<std::pair<std::string, std::variant<std::int64_t, double, bool, std::string>>> extra;

  std::optional<double> foveal_error_deg() const;
  // The gaze sample's host times where 0 means "none measured" (the OpenXR paths' convention).
  void set_gaze_times(core::TimeNs sample, core::TimeNs receive, core::TimeNs read);
  void set_frame_calls(core::TimeNs wait_call, core::TimeNs wait_return, core::TimeNs begin, core::TimeNs end_call,
                       core::TimeNs end_return);
};

const char* time_base_name(TimeBase b);  // "monotonic" | "virtual"

// The record as one line of JSON ending in '\n'. Non-finite numbers are written as 0 (and a
// non-finite direction as absent): outputs never contain NaN or Inf.
std::string to_json_line(const TimingRecord& r);
// One line back; throws core::InputError naming `where` (file:line) and the bad field.
TimingRecord parse_timing_record(std::string_view line, const std::string& where);

}  // namespace fovea::xrcommon
