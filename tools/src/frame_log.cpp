#include "frame_log.hpp"

#include <cmath>

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
  nlohmann::json t = {{"frame", r.frame}, {"gaze_read_ns", g.read_ns}};
  for (const auto& [k, v] : r.timings_ms) t[k] = std::isfinite(v) ? v : 0.0;
  times_ += t.dump() + "\n";
}

void FrameLog::finish() const {
  core::write_file_atomic(path_, text_);
  core::write_file_atomic(times_path_, times_);
}

}  // namespace fovea::tools
