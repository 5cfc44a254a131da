// The resolve stage (grid-image copy, recon_mip.comp, recon_resolve.comp with the display depth,
// recon_blur.comp): GPU time of each part, both eyes, for a display
// preset, a distribution and a gaze. One frame of the `default` scene is rendered first
// (1 bounce, so the grid holds a real image); then each iteration resolves that frame's
// grids again and times the parts with timestamps (the benchmark's time is their sum).
// Counters: copy_ms, mip_ms, resample_ms, blur_ms, and the process CPU time of each
// (*_cpu_ms: lavapipe's work, which other load on the machine inflates less). The /depth
// variants also write the display depth, as the layer's depth compositing asks for.
//   LP_NUM_THREADS=2 fovea_bench_resolve --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <string>

#include "fovea/core/display.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/pipeline/testing.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "default_scene.hpp"

namespace fp = fovea::pipeline;
namespace fc = fovea::core;

namespace {

using fovea::bench::context;
using fovea::bench::gpu_scene;
using fovea::bench::scene;

// Gaze `deg` degrees off the view axis, towards the upper right (a corner: the largest
// eccentricities on the opposite side).
glm::dvec3 gaze_at(double deg) {
  const double t = std::tan(deg * M_PI / 180) / std::sqrt(2.0);
  return glm::normalize(glm::dvec3(t, t, -1));
}

void resolve(benchmark::State& state, std::string display, fc::DistributionKind kind, double gaze_deg, bool depth) {
  const fc::DisplayPreset d = fc::load_display(display);
  fc::DistributionParams dp;
  dp.kind = kind;
  fovea::reconstruct::ReconSettings s;
  fp::FramePipeline p(context(), gpu_scene(), fc::stereo_views(d), dp, s);
  if (depth) p.enable_depth_output();
  const glm::dvec3 g = gaze_at(gaze_deg);
  p.render(fc::eye_poses(scene().camera, d), {g, g}, 0);
  fp::testing::ResolveKernelTimes sum;
  const auto add = [](fp::testing::KernelTime& a, const fp::testing::KernelTime& b) {
    a.gpu_ms += b.gpu_ms, a.cpu_ms += b.cpu_ms;
  };
  for (auto _ : state) {
    const fp::testing::ResolveKernelTimes t = fp::testing::time_resolve(p, s.blur);
    state.SetIterationTime((t.copy.gpu_ms + t.mip.gpu_ms + t.resample.gpu_ms + t.blur.gpu_ms) * 1e-3);
    add(sum.copy, t.copy), add(sum.mip, t.mip), add(sum.resample, t.resample), add(sum.blur, t.blur);
  }
  const double n = double(state.iterations());
  for (const auto& [name, k] : {std::pair{"copy", sum.copy}, std::pair{"mip", sum.mip}, std::pair{"resample", sum.resample}, std::pair{"blur", sum.blur}}) {
    state.counters[std::string(name) + "_ms"] = k.gpu_ms / n;
    state.counters[std::string(name) + "_cpu_ms"] = k.cpu_ms / n;
  }
}

void register_all() {
  for (const char* display : {"small", "fove0"})
    for (const auto& [name, kind] : {std::pair{"visual-polar", fc::DistributionKind::VisualPolar},
                                     std::pair{"cartesian", fc::DistributionKind::Cartesian}})
      for (const double gaze : {0.0, 25.0})
        for (const bool depth : {false, true})
          benchmark::RegisterBenchmark((std::string("Resolve/") + display + "/" + name + "/gaze" +
                                        std::to_string(int(gaze)) + (depth ? "/depth" : ""))
                                           .c_str(),
                                       [=](benchmark::State& st) { resolve(st, display, kind, gaze, depth); })
              ->UseManualTime()
              ->Unit(benchmark::kMillisecond)
              ->Iterations(display == std::string("fove0") ? 3 : 10);
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
