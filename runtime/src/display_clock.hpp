#pragma once
// The simulated panel's clock: the display model's frame pacer (vsyncs every 1/refresh
// seconds, in int64 ns of CLOCK_MONOTONIC), shared with `fovea latency` so that both pace and
// display frames by one model (fovea/xrcommon/display_model.hpp, docs/latency.md).
#include "fovea/xrcommon/display_model.hpp"

namespace fovea::runtime {

using DisplayClock = xrcommon::FramePacer;
using xrcommon::FrameSlot;
using xrcommon::Pacing;

}  // namespace fovea::runtime
