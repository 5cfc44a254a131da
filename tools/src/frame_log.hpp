#pragma once
// frames.jsonl of `fovea render`: one JSON object per frame, the test oracle of a replay.
// Every field is a deterministic function of the inputs, so two identical runs write the
// same bytes (`fovea replay-diff` compares with tolerances); the per-stage timings of each
// frame go to frame_times.jsonl beside it as timing records (fovea/xrcommon/timing_record.hpp).
#include <array>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "fovea/core/view.hpp"
#include "fovea/devices/foveation_gaze.hpp"
#include "fovea/xrcommon/timing_writer.hpp"

namespace fovea::tools {

struct FrameRecord {
  long frame = 0;
  core::TimeNs t_ns = 0;              // the frame's time on the gaze timeline
  devices::FoveaGaze gaze;            // the foveation gaze used for t_ns
  std::array<glm::dvec3, 2> used{};   // the gaze each eye was rendered with (left, right)
  std::array<core::Pose, 2> poses{};  // eye poses (left, right)
  int grid_columns = 0, grid_rows = 0;
  std::vector<std::pair<std::string, double>> cpu_ms, gpu_ms;  // per stage
  bool live = false;  // the gaze came from a live source: its times are CLOCK_MONOTONIC, not the frame timeline
};

// frames.jsonl is held in memory (a few hundred bytes per frame) and written by finish();
// frame_times.jsonl is written as it goes under a temporary name; finish() renames both
// into place, like every output.
class FrameLog {
 public:
  // `frames_path` (deterministic) and `times_path` (timings), one line per frame each.
  FrameLog(std::string frames_path, const std::string& times_path);
  void add(const FrameRecord& r);
  void finish();

 private:
  std::string path_, text_;
  xrcommon::TimingWriter times_;
};

}  // namespace fovea::tools
