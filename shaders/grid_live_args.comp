#version 460
// The live-cell list's header (live_cells.h) from the grid pass's counts: one invocation,
// after grid_generate.comp. Each dispatch's workgroups are folded into rows of at most
// max_groups_x, as even as the rounding allows (gpu::ComputePipeline::dispatch_linear).
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 1) in;

#include "fovea/shaders/live_cells.h"

layout(std430, set = 0, binding = 0) readonly buffer Counts { GridCounts counts; };
layout(std430, set = 0, binding = 1) writeonly buffer List { uint header[kLiveHeaderWords]; };
layout(push_constant) uniform Push { uint max_groups_x; };

void write_args(uint at, uint invocations) {
  const uint groups = (invocations + kLiveGroupSize - 1u) / kLiveGroupSize;
  const uint rows = max(1u, (groups + max_groups_x - 1u) / max_groups_x);
  header[at] = (groups + rows - 1u) / rows;
  header[at + 1u] = groups == 0u ? 0u : rows;
  header[at + 2u] = 1u;
}

void main() {
  write_args(kLiveArgsLive, counts.live);
  header[kLiveCount] = counts.live;
  write_args(kLiveArgsChanged, counts.live + counts.reset);
  header[kLiveResetCount] = counts.reset;
}
