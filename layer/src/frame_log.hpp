#pragma once
// The layer's per-frame timing log (pass-through measurement): one timing record
// (fovea/xrcommon/timing_record.hpp) per line in <FOVEA_LAYER_OUT>/layer_timing.jsonl.
// Times are int64 ns of CLOCK_MONOTONIC.
#include <cstdint>
#include <string>

#include "fovea/xrcommon/timing_writer.hpp"
#include "frame_renderer.hpp"

namespace fovea::layer {

std::int64_t now_ns();

struct FrameTimes {
  std::int64_t frame = 0;
  std::int64_t display_time_ns = 0;               // predicted by xrWaitFrame
  std::int64_t wait_call_ns = 0, wait_return_ns = 0;
  std::int64_t begin_ns = 0;
  std::int64_t end_call_ns = 0, end_return_ns = 0;  // around the call down the chain
  std::int64_t end_down_ns = 0;  // the call down the chain began (the layer's own work before it)
  std::uint32_t layers = 0, projection_views = 0;
  bool replaced = false;  // a frame renderer replaced the application's layers
  // What the frame renderer showed (Shown's defaults when not replaced: no traced frame, -1):
  // the path-traced frame, where it was composited, its render's split and this frame's.
  Shown shown;
};

class FrameLog {
 public:
  void open(const std::string& dir);  // empty: no log
  void write(const FrameTimes& t);

 private:
  xrcommon::TimingWriter writer_;
};

}  // namespace fovea::layer
