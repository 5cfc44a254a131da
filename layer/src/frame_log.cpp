#include "frame_log.hpp"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>

#include "fovea/xrcommon/output_dir.hpp"
#include "log.hpp"

namespace fovea::layer {

// About 3.5 s of frames at 72 Hz before write() has to grow a buffer.
constexpr std::size_t kBufferedRecords = 256;

FrameLog::~FrameLog() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  stop_cv_.notify_all();
  thread_.join();
}

namespace {

// What the process's logs share: the session numbers and the files already started (a later
// session appends to them instead of truncating the earlier sessions' records).
struct ProcessLogs {
  std::mutex mutex;
  std::int64_t sessions = 0;
  std::set<std::string> started;
};

ProcessLogs& process_logs() {
  static ProcessLogs p;
  return p;
}

}  // namespace

void FrameLog::open(const std::string& dir) {
  if (dir.empty()) return;
  ProcessLogs& p = process_logs();
  std::lock_guard process_lock(p.mutex);
  session_ = p.sessions++;
  try {
    xrcommon::create_output_dir(dir, "FOVEA_LAYER_OUT");  // as the runtime creates FOVEA_RUNTIME_OUT
    const std::string file = std::filesystem::absolute(dir + "/layer_timing.jsonl").lexically_normal().string();
    const bool started = p.started.count(file) > 0;
    writer_.open(file, started ? xrcommon::TimingWriter::Mode::Append : xrcommon::TimingWriter::Mode::Stream);
    p.started.insert(file);
  } catch (const std::exception& e) {
    // Reported, not fatal: the session works, its frames are just not logged.
    FOVEA_LAYER_WARN("%s; frames are not logged", e.what());
    return;
  }
  pending_.reserve(kBufferedRecords);
  thread_ = std::thread([this] { run(); });
}

void FrameLog::write(const FrameTimes& t) {
  if (!thread_.joinable()) return;
  std::lock_guard lock(mutex_);
  pending_.push_back(t);
}

void FrameLog::run() {
  pthread_setname_np(pthread_self(), "fovea-log");
  // Below the application's threads: the log is never urgent.
  if (setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19) != 0)
    FOVEA_LAYER_WARN("timing log thread: cannot set nice 19 (%s)", std::strerror(errno));
  std::vector<FrameTimes> batch;
  batch.reserve(kBufferedRecords);
  for (bool last = false; !last;) {
    {
      std::unique_lock lock(mutex_);
      last = stop_cv_.wait_for(lock, kFlushPeriod, [&] { return stop_; });
      batch.swap(pending_);  // pending_ gets the emptied buffer back, its capacity kept
    }
    for (const FrameTimes& t : batch) write_now(t);
    batch.clear();
  }
}

void FrameLog::write_now(const FrameTimes& t) {
  if (!writer_.is_open()) return;  // a write failed earlier (reported then)
  const RenderTimes& rt = t.shown.times;
  xrcommon::TimingRecord r;
  r.source = "layer";
  r.frame = t.frame;
  r.session = session_;
  r.gaze_valid = rt.gaze_sample_ns != 0;  // 0: no tracker sample measured yet (or no renderer)
  r.set_gaze_times(rt.gaze_sample_ns, rt.gaze_receive_ns, rt.gaze_read_ns);
  r.predicted_display_ns = t.display_time_ns;
  r.set_frame_calls(t.wait_call_ns, t.wait_return_ns, t.begin_ns, t.end_call_ns, t.end_return_ns);
  r.cpu_ms = {{"app", double(t.end_call_ns - t.begin_ns) * 1e-6},
              {"end_frame", double(t.end_return_ns - t.end_call_ns) * 1e-6},
              {"end_frame_layer", double(t.end_down_ns - t.end_call_ns) * 1e-6},
              {"readback", rt.readback_cpu}};
  const auto frame_cpu = rt.frame.cpu_record(rt.gaze_cpu);  // the frame driver's step: gaze ... total
  r.cpu_ms.insert(r.cpu_ms.end(), frame_cpu.begin(), frame_cpu.end());
  r.gpu_ms = rt.frame.gpu_record();
  r.extra = {// Which clock the runtime's XrTime values are on (FrameTimes::xr_time_converted).
             {"xr_time_converted", t.xr_time_converted},
             {"layers", std::int64_t(t.layers)},     {"projection_views", std::int64_t(t.projection_views)},
             {"replaced", t.replaced},                {"render_ms", rt.total},
             {"transfer_ms", rt.transfer},            {"samples_traced", rt.samples_traced},
             {"samples_hidden", rt.samples_hidden},
             // Which path-traced frame this displayed frame shows (asynchronous rendering).
             {"traced_frame", t.shown.frame},         {"traced_for_ns", t.shown.traced_for_ns},
             {"traced_for_frame", t.shown.traced_for_frame},
             {"traced_done_ns", t.shown.done_ns},
             {"traced_age_ns", t.shown.frame >= 0 ? t.display_time_ns - t.shown.traced_for_ns : std::int64_t(0)},
             {"reprojected_deg", std::isfinite(t.shown.reprojected_deg) ? t.shown.reprojected_deg : 0.0},
             {"composited_on_gpu", t.shown.composited_on_gpu}, {"host_readbacks", t.shown.host_readbacks},
             // The GPU composition's work on the application's thread (counts so far).
             {"traced_slot", std::int64_t(t.shown.traced_slot)}, {"recordings", t.shown.recordings},
             {"descriptor_updates", t.shown.descriptor_updates}, {"reuse_waits", t.shown.reuse_waits},
             {"acquire_waits", t.shown.acquire_waits},
             {"acquire_ms", t.shown.acquire_ms}, {"compose_ms", t.shown.compose_ms},
             {"release_ms", t.shown.release_ms}, {"submit_ms", t.shown.submit_ms},
             {"submit_preemptions", t.shown.submit_preemptions},
             // How the shown traced frame reached the application's device (RenderTimes::handover).
             {"handover", std::string(rt.handover)}, {"host_bytes", rt.host_bytes}};
  if (!writer_.write(r)) FOVEA_LAYER_WARN("%s", writer_.error().c_str());
}

}  // namespace fovea::layer
