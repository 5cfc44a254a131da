#include "timing_log.hpp"

#include <stdexcept>

#include "log.hpp"

namespace fovea::runtime {

void TimingLog::open(const std::string& dir) {
  writer_ = xrcommon::TimingWriter();
  if (dir.empty()) return;
  try {
    writer_.open(dir + "/timing.jsonl");
  } catch (const std::runtime_error& e) {
    FOVEA_LOG_ERROR("%s", e.what());
  }
}

void TimingLog::write(const FrameRecord& r) {
  if (!writer_.is_open()) return;
  xrcommon::TimingRecord t;
  t.source = "runtime";
  t.frame = r.frame;
  t.gaze_valid = r.gaze_valid;
  t.set_gaze_times(r.gaze_sample_ns, r.gaze_receive_ns, r.gaze_read_ns);  // the runtime's sources carry no device clock
  if (r.head_pose_ns) {
    t.head_pose_ns = r.head_pose_ns;
    t.head_pose_target_ns = r.head_pose_target_ns;
  }
  t.predicted_display_ns = r.predicted_display_ns;
  t.set_frame_calls(r.wait_call_ns, r.wait_return_ns, r.begin_ns, r.end_call_ns, r.end_return_ns);
  t.submit_ns = r.end_call_ns;  // the panel images after it are the simulator's, not the frame's
  t.vsync_ns = r.displayed_ns;
  t.missed_vsyncs = r.missed_vsyncs;
  t.photon_ns = r.photon;
  if (r.gaze_valid) t.fovea_dir = r.gaze_dir;  // an untracked read says nothing of the fovea
  t.true_gaze_dir = r.true_gaze_dir;
  t.cpu_ms = {{"validate", r.cpu_validate_ms}, {"gaze", r.cpu_gaze_ms},   {"readback", r.cpu_readback_ms},
              {"resample", r.cpu_resample_ms}, {"lens", r.cpu_lens_ms}, {"write", r.cpu_write_ms}};
  t.extra = {{"late_ns", r.late_ns}, {"compositor_ms", r.compositor_ms}, {"composited", r.composited},
             {"layers", std::int64_t(r.layers)}};
  if (!writer_.write(t)) FOVEA_LOG_ERROR("%s", writer_.error().c_str());
}

}  // namespace fovea::runtime
