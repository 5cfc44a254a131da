#include "frame_log.hpp"

#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "fovea/core/image.hpp"

namespace fovea::tools {

namespace {
nlohmann::json vec(const glm::dvec3& v) {
  // Outputs never hold NaN/Inf: a non-finite direction is written as null.
  if (!std::isfinite(v.x + v.y + v.z)) return nullptr;
  return {v.x, v.y, v.z};
}
nlohmann::json eye(const devices::FoveaEye& g) {
  return {{"dir", vec(g.dir)},
          {"flags", g.flags},
          {"confidence", std::isfinite(g.confidence) ? g.confidence : 0.0},
          {"tracked", g.tracked()}};
}
}  // namespace

FrameLog::FrameLog(std::string frames_path, const std::string& times_path) : path_(std::move(frames_path)) {
  times_.open(times_path, xrcommon::TimingWriter::Mode::Atomic);
}

void FrameLog::add(const FrameRecord& r) {
  const devices::FoveaGaze& g = r.gaze;
  nlohmann::json j;
  j["frame"] = r.frame;
  j["t_ns"] = r.t_ns;
  // The newest real sample behind the fovea, on the gaze timeline (none: null times). The
  // host time at which it was read is a timing and goes to frame_times.jsonl.
  const auto when = [&](core::TimeNs t) -> nlohmann::json { return g.has_sample ? nlohmann::json(t) : nullptr; };
  j["gaze"] = {{"sample_ns", when(g.sample_ns)},
               {"device_ns", when(g.device_ns)},
               {"receive_ns", when(g.receive_ns)},
               {"combined", eye(g.combined)},
               {"left", eye(g.left)},
               {"right", eye(g.right)}};
  j["used_gaze"] = {{"left", vec(r.used[0])}, {"right", vec(r.used[1])}};
  nlohmann::json poses = nlohmann::json::array();
  for (const core::Pose& p : r.poses) {
    const glm::dquat& q = p.orientation;
    poses.push_back({{"position", vec(p.position)}, {"orientation_wxyz", {q.w, q.x, q.y, q.z}}});
  }
  j["eye_poses"] = poses;
  j["grid"] = {r.grid_columns, r.grid_rows};
  text_ += j.dump() + "\n";
  // The timing record: on the frame timeline (the gaze read at the frame's time t_ns), or
  // the host clock for a live source.
  xrcommon::TimingRecord t;
  t.source = "render";
  t.clock = r.live ? xrcommon::TimeBase::Monotonic : xrcommon::TimeBase::Virtual;
  t.frame = r.frame;
  t.gaze_valid = g.combined.tracked();
  if (g.has_sample) {
    t.gaze_sample_ns = g.sample_ns;
    t.gaze_device_ns = g.device_ns;
    t.gaze_receive_ns = g.receive_ns;
  }
  t.gaze_read_ns = r.live ? g.read_ns : r.t_ns;
  t.predicted_display_ns = r.t_ns;
  t.cpu_ms = r.cpu_ms;
  t.gpu_ms = r.gpu_ms;
  t.fovea_dir = g.combined.dir;
  if (!times_.write(t)) throw std::runtime_error(times_.error());
}

void FrameLog::finish() {
  core::write_file_atomic(path_, text_);
  times_.close();
}

}  // namespace fovea::tools
