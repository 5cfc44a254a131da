#version 460
// Test shader for the gpu module: data[i] = i * kScale + offset + bias for i < count.
// The workgroup width is a specialization constant (id 1, default 64) so tests can check
// that dispatch rounding follows the specialized size; invocations are indexed as
// dispatch_linear folds them (FOVEA_LINEAR_INVOCATION), which a plain 1-D dispatch equals.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 64, local_size_x_id = 1) in;

#include "fovea/shaders/common.h"

layout(constant_id = 0) const uint kScale = 1;

layout(push_constant) uniform Push {
  uint count;
  uint offset;
} pc;

layout(set = 0, binding = 0) writeonly buffer Out { uint data[]; };
layout(set = 0, binding = 1) uniform Params { uint bias; };

void main() {
  uint i = FOVEA_LINEAR_INVOCATION;
  if (i >= pc.count) return;
  data[i] = i * kScale + pc.offset + bias;
}
