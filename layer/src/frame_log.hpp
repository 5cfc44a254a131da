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
  // The path-traced frame shown (-1: none finished yet, or no renderer): its number, the
  // display time it was traced for (its age is display_time_ns - traced_for_ns), when it
  // finished, and the head rotation reprojected since (degrees, the larger of the two eyes).
  std::int64_t traced_frame = -1;
  std::int64_t traced_for_ns = 0, traced_done_ns = 0;
  double reprojected_deg = 0;
  // Where the shown frame was composited, and how many application images went to the host.
  bool composited_on_gpu = false;
  std::int64_t host_readbacks = 0;
  Shown shown;  // the rest of what the frame renderer reported (its slot, counters and split)
  RenderTimes render;     // the frame renderer's split of the traced frame (zero without one)
};

class FrameLog {
 public:
  void open(const std::string& dir);  // empty: no log
  void write(const FrameTimes& t);

 private:
  xrcommon::TimingWriter writer_;
};

}  // namespace fovea::layer
