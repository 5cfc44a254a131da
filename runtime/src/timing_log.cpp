#include "timing_log.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>

#include "log.hpp"

namespace fovea::runtime {

TimingLog::~TimingLog() {
  if (file_) std::fclose(file_);
}

void TimingLog::open(const std::string& dir) {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  if (dir.empty()) return;
  path_ = dir + "/timing.jsonl";
  file_ = std::fopen(path_.c_str(), "w");
  if (!file_) FOVEA_LOG_ERROR("timing log %s: cannot open: %s", path_.c_str(), std::strerror(errno));
}

namespace {
double finite_or_zero(double ms) { return std::isfinite(ms) ? ms : 0.0; }
}  // namespace

void TimingLog::write(const FrameRecord& r) {
  if (!file_) return;
  const double ms = finite_or_zero(r.compositor_ms);
  const int n = std::fprintf(
      file_,
      "{\"frame\":%lld,\"predicted_display_ns\":%lld,\"wait_call_ns\":%lld,\"wait_return_ns\":%lld,"
      "\"late_ns\":%lld,\"missed_vsyncs\":%lld,\"begin_ns\":%lld,\"end_call_ns\":%lld,\"end_return_ns\":%lld,"
      "\"displayed_ns\":%lld,\"compositor_ms\":%.3f,\"composited\":%s,\"layers\":%u,\"gaze_sample_ns\":%lld,"
      "\"gaze_receive_ns\":%lld,\"gaze_read_ns\":%lld,\"gaze_valid\":%s,\"cpu_ms\":{\"validate\":%.3f,"
      "\"gaze\":%.3f,\"readback\":%.3f,\"resample\":%.3f,\"lens\":%.3f,\"write\":%.3f}}\n",
      static_cast<long long>(r.frame), static_cast<long long>(r.predicted_display_ns),
      static_cast<long long>(r.wait_call_ns), static_cast<long long>(r.wait_return_ns),
      static_cast<long long>(r.late_ns), static_cast<long long>(r.missed_vsyncs), static_cast<long long>(r.begin_ns),
      static_cast<long long>(r.end_call_ns), static_cast<long long>(r.end_return_ns),
      static_cast<long long>(r.displayed_ns), ms, r.composited ? "true" : "false", r.layers,
      static_cast<long long>(r.gaze_sample_ns), static_cast<long long>(r.gaze_receive_ns),
      static_cast<long long>(r.gaze_read_ns), r.gaze_valid ? "true" : "false", finite_or_zero(r.cpu_validate_ms),
      finite_or_zero(r.cpu_gaze_ms), finite_or_zero(r.cpu_readback_ms), finite_or_zero(r.cpu_resample_ms),
      finite_or_zero(r.cpu_lens_ms), finite_or_zero(r.cpu_write_ms));
  if (n < 0 || std::fflush(file_) != 0) {
    FOVEA_LOG_ERROR("timing log %s: write failed at frame %lld: %s; no further records", path_.c_str(),
                    static_cast<long long>(r.frame), std::strerror(errno));
    std::fclose(file_);
    file_ = nullptr;
  }
}

}  // namespace fovea::runtime
