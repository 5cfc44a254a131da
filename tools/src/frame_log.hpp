#pragma once
// frames.jsonl of `fovea render`: one JSON object per frame, the test oracle of a replay.
// Every field but "timings_ms" is a deterministic function of the inputs, so two runs are
// compared field for field (`fovea replay-diff`); timings are kept under their own key.
#include <array>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "fovea/core/view.hpp"
#include "fovea/devices/gaze.hpp"

namespace fovea::tools {

struct FrameRecord {
  long frame = 0;
  core::TimeNs t_ns = 0;              // the frame's time on the gaze timeline
  devices::GazeSample sample;         // what the source returned for t_ns
  std::array<glm::dvec3, 2> used{};   // the gaze each eye was rendered with (left, right)
  std::array<core::Pose, 2> poses{};  // eye poses (left, right)
  int grid_columns = 0, grid_rows = 0;
  std::vector<std::pair<const char*, double>> timings_ms;  // per stage
};

// Held in memory (a few hundred bytes per frame) and written by finish() through a
// temporary name and a rename, like every output.
class FrameLog {
 public:
  explicit FrameLog(std::string path) : path_(std::move(path)) {}
  void add(const FrameRecord& r);
  void finish() const;

 private:
  std::string path_, text_;
};

}  // namespace fovea::tools
