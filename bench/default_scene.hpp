#pragma once
// The benchmarks' device and the shipped `default` scene on it, made once per process.
#include "fovea/gpu/context.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/scene_io.hpp"

namespace fovea::bench {

inline gpu::Context& context() {
  static gpu::Context ctx;
  return ctx;
}

inline const renderer::Scene& scene() {
  static const renderer::Scene s = renderer::load_scene("default");
  return s;
}

inline const renderer::GpuScene& gpu_scene() {
  static const renderer::GpuScene gs(context(), scene());
  return gs;
}

}  // namespace fovea::bench
