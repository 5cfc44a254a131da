#include "timing_log.hpp"

#include <cmath>

namespace fovea::runtime {

TimingLog::~TimingLog() {
  if (file_) std::fclose(file_);
}

void TimingLog::open(const std::string& dir) {
  if (file_) std::fclose(file_);
  file_ = dir.empty() ? nullptr : std::fopen((dir + "/timing.jsonl").c_str(), "w");
}

void TimingLog::write(const FrameRecord& r) {
  if (!file_) return;
  const double ms = std::isfinite(r.compositor_ms) ? r.compositor_ms : 0.0;
  std::fprintf(file_,
               "{\"frame\":%lld,\"predicted_display_ns\":%lld,\"wait_call_ns\":%lld,\"wait_return_ns\":%lld,"
               "\"late_ns\":%lld,\"begin_ns\":%lld,\"end_call_ns\":%lld,\"end_return_ns\":%lld,"
               "\"compositor_ms\":%.3f,\"composited\":%s,\"layers\":%u,\"gaze_sample_ns\":%lld,\"gaze_receive_ns\":%lld,"
               "\"gaze_read_ns\":%lld,\"gaze_valid\":%s}\n",
               static_cast<long long>(r.frame), static_cast<long long>(r.predicted_display_ns),
               static_cast<long long>(r.wait_call_ns), static_cast<long long>(r.wait_return_ns),
               static_cast<long long>(r.late_ns), static_cast<long long>(r.begin_ns),
               static_cast<long long>(r.end_call_ns), static_cast<long long>(r.end_return_ns), ms,
               r.composited ? "true" : "false", r.layers, static_cast<long long>(r.gaze_sample_ns),
               static_cast<long long>(r.gaze_receive_ns), static_cast<long long>(r.gaze_read_ns), r.gaze_valid ? "true" : "false");
  std::fflush(file_);
}

}  // namespace fovea::runtime
