#version 460
// The API layer's traced eye for the application's swapchain, on the layer's device: the
// displayed linear radiance tone mapped (core/tonemap.hpp), encoded as the swapchain stores
// it (sRGB OETF or linear UNORM, 8 bits, RGBA or BGRA, alpha 1) and written into a slot the
// application's device reads: what the host path's encode_scene (layer/src/composite.cpp)
// does on the host, without reading the image back.
#extension GL_GOOGLE_include_directive : require
#include "fovea/shaders/layer_encode.h"

layout(local_size_x = kEncodeGroup) in;

layout(push_constant) uniform Push { EncodePush pc; };

layout(std430, set = 0, binding = ENCODE_BINDING_SCREEN) readonly buffer Screen { vec4 screen[]; };
layout(std430, set = 0, binding = ENCODE_BINDING_SLOTS) writeonly buffer Slots { uint slots[]; };

float aces(float x) {
  return (kAcesK0 * x * x + kAcesK1 * x) / (kAcesK3 * x * x + kAcesK4 * x + kAcesK5);
}

// One channel: non-finite and negative radiance count as 0 (as on the host), huge radiance
// saturates (x capped before squaring: no overflow to Inf/Inf).
uint encode(float v) {
  float x = (isnan(v) || isinf(v)) ? 0.0 : clamp(v, 0.0, 1e18);
  float t = clamp(aces(x), 0.0, 1.0);
  if (pc.srgb != 0u) t = t <= 0.0031308 ? 12.92 * t : 1.055 * pow(t, 1.0 / 2.4) - 0.055;
  return uint(round(clamp(t, 0.0, 1.0) * 255.0));
}

void main() {
  uint i = FOVEA_LINEAR_INVOCATION;
  if (i >= pc.pixels) return;
  vec4 c = screen[i];
  uint r = encode(c.r), g = encode(c.g), b = encode(c.b);
  uint first = pc.bgra != 0u ? b : r, third = pc.bgra != 0u ? r : b;
  slots[pc.first_word + i] = first | (g << 8) | (third << 16) | (255u << 24);
}
