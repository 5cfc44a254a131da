#include "frame_log.hpp"

#include <time.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "log.hpp"

namespace fovea::layer {

std::int64_t now_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

FrameLog::~FrameLog() {
  if (file_) std::fclose(file_);
}

void FrameLog::open(const std::string& dir) {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  if (dir.empty()) return;
  const std::string path = dir + "/layer_timing.jsonl";
  file_ = std::fopen(path.c_str(), "w");
  // Reported, not fatal: the session works, its frames are just not logged.
  if (!file_)
    FOVEA_LAYER_WARN("cannot write the timing log \"%s\" (FOVEA_LAYER_OUT): %s; frames are not logged", path.c_str(),
                     std::strerror(errno));
}

void FrameLog::write(const FrameTimes& t) {
  if (!file_) return;
  std::fprintf(file_,
               "{\"frame\":%lld,\"display_time_ns\":%lld,\"wait_call_ns\":%lld,\"wait_return_ns\":%lld,"
               "\"begin_ns\":%lld,\"end_call_ns\":%lld,\"end_return_ns\":%lld,\"app_cpu_ms\":%.3f,"
               "\"end_frame_ms\":%.3f,\"layers\":%u,\"projection_views\":%u,\"replaced\":%s,\"render_ms\":%.3f,"
               "\"trace_ms\":%.3f,\"reconstruct_ms\":%.3f,\"resolve_ms\":%.3f,\"transfer_ms\":%.3f,"
               "\"gaze_cpu_ms\":%.3f,\"grid_cpu_ms\":%.3f,\"submit_cpu_ms\":%.3f,\"readback_cpu_ms\":%.3f,"
               "\"gaze_sample_ns\":%lld,\"gaze_receive_ns\":%lld,\"gaze_read_ns\":%lld,\"samples_hidden\":%lld,"
               "\"traced_frame\":%lld,\"traced_for_ns\":%lld,\"traced_done_ns\":%lld,\"traced_age_ns\":%lld,"
               "\"reprojected_deg\":%.4f}\n",
               static_cast<long long>(t.frame), static_cast<long long>(t.display_time_ns),
               static_cast<long long>(t.wait_call_ns), static_cast<long long>(t.wait_return_ns),
               static_cast<long long>(t.begin_ns), static_cast<long long>(t.end_call_ns),
               static_cast<long long>(t.end_return_ns), double(t.end_call_ns - t.begin_ns) * 1e-6,
               double(t.end_return_ns - t.end_call_ns) * 1e-6, t.layers, t.projection_views,
               t.replaced ? "true" : "false", t.render.total, t.render.trace, t.render.reconstruct, t.render.resolve,
               t.render.transfer, t.render.gaze_cpu, t.render.grid_cpu, t.render.submit_cpu, t.render.readback_cpu,
               static_cast<long long>(t.render.gaze_sample_ns), static_cast<long long>(t.render.gaze_receive_ns),
               static_cast<long long>(t.render.gaze_read_ns), static_cast<long long>(t.render.samples_hidden),
               static_cast<long long>(t.traced_frame), static_cast<long long>(t.traced_for_ns),
               static_cast<long long>(t.traced_done_ns),
               static_cast<long long>(t.traced_frame >= 0 ? t.display_time_ns - t.traced_for_ns : 0),
               std::isfinite(t.reprojected_deg) ? t.reprojected_deg : 0.0);
  std::fflush(file_);
}

}  // namespace fovea::layer
