#pragma once
// The layer's per-frame timing log (pass-through measurement): one timing record
// (fovea/xrcommon/timing_record.hpp) per line in <FOVEA_LAYER_OUT>/layer_timing.jsonl, the
// records of all the process's sessions.
// Times are int64 ns of CLOCK_MONOTONIC; the runtime's XrTime values are converted to it where
// the runtime can (FrameTimes::xr_time_converted says whether they were).
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fovea/core/clock.hpp"
#include "fovea/xrcommon/timing_writer.hpp"
#include "frame_renderer.hpp"

namespace fovea::layer {

struct FrameTimes {
  std::int64_t frame = 0;
  std::int64_t display_time_ns = 0;               // predicted by xrWaitFrame
  std::int64_t wait_call_ns = 0, wait_return_ns = 0;
  std::int64_t begin_ns = 0;
  std::int64_t end_call_ns = 0, end_return_ns = 0;  // around the call down the chain
  std::int64_t end_down_ns = 0;  // the call down the chain began (the layer's own work before it)
  std::uint32_t layers = 0, projection_views = 0;
  bool replaced = false;  // a frame renderer replaced the application's layers
  // The runtime's XrTime values (display_time_ns, shown.traced_for_ns, and the gaze sample's
  // times unless shown.times.gaze_on_host_clock) were converted to CLOCK_MONOTONIC with
  // XR_KHR_convert_timespec_time; false: they are the runtime's XrTime as it gave them.
  bool xr_time_converted = false;
  // What the frame renderer showed (Shown's defaults when not replaced: no traced frame, -1):
  // the path-traced frame, where it was composited, its render's split and this frame's.
  Shown shown;
};

// Records are formatted and written by the log's own thread at nice 19, not by the
// application's thread in xrEndFrame: formatting a record and its write(2) took about 65 µs
// a frame (`small`, lavapipe), half of pass-through's whole xrEndFrame.
// write() only appends the record to a buffer; the thread takes the buffer every
// kFlushPeriod without being woken per frame (a woken thread of the application's priority
// may take the application's core), so the file lags the frames by up to that period (and
// longer when the machine leaves the thread no core). The destructor writes what is left.
class FrameLog {
 public:
  static constexpr std::chrono::milliseconds kFlushPeriod{50};

  FrameLog() = default;
  ~FrameLog();
  FrameLog(const FrameLog&) = delete;
  FrameLog& operator=(const FrameLog&) = delete;

  // Numbers the session (from 0, in the order sessions open their logs in the process) and
  // starts logging to <dir>/layer_timing.jsonl: the process's first log there truncates the
  // file, later ones append, so the file holds every session of the process, each record
  // naming its session. Empty `dir`: no log. Call once, before write().
  void open(const std::string& dir);
  std::int64_t session() const { return session_; }
  // Any thread. No allocation while the writer keeps up (the buffers keep their capacity).
  void write(const FrameTimes& t);

 private:
  void run();
  void write_now(const FrameTimes& t);

  xrcommon::TimingWriter writer_;  // the writer thread's once it runs
  std::int64_t session_ = -1;
  std::mutex mutex_;
  std::condition_variable stop_cv_;
  bool stop_ = false;
  std::vector<FrameTimes> pending_;  // appended by write(), swapped out by run()
  std::thread thread_;
};

}  // namespace fovea::layer
