// One stereo frame of the whole pipeline, as `fovea render` runs it, per display preset and
// distribution: the table of GPU and CPU time per frame on any Vulkan device. Each
// iteration renders one frame of the `default` scene (gaze sweeping 10 degrees around the
// centre, history and BMFR as in a render) and then, apart, reads both eyes back as a
// render that wrote every frame would. Counters (means per frame):
//   gpu_total_ms, trace_ms, reconstruct_ms, bmfr_fit_ms, resolve_ms   GPU timestamps
//   cpu_frame_ms   the frame's CPU time: grid update, recording, submit and fence wait
//   readback_ms    reading both eyes back (output work, not part of the frame)
//   readback_bytes, samples_per_eye
// The benchmark's time is gpu_total_ms. Displays: FOVEA_BENCH_DISPLAYS (comma-separated,
// default "small,fove0"; e.g. "fove0,modern" on a discrete GPU).
//   FOVEA_BENCH_DISPLAYS=fove0,modern fovea_bench_frame --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "fovea/core/clock.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "default_scene.hpp"

namespace fp = fovea::pipeline;
namespace fc = fovea::core;

namespace {

using fovea::bench::context;
using fovea::bench::gpu_scene;
using fovea::bench::scene;

void frame(benchmark::State& state, const std::string& display, fc::DistributionKind kind) {
  const fc::DisplayPreset d = fc::load_display(display);
  fc::DistributionParams dp;
  dp.kind = kind;
  if (kind == fc::DistributionKind::Cartesian) dp.budget = 1.0;
  dp.display = d.origin;
  fp::FramePipeline p(context(), gpu_scene(), fc::stereo_views(d), dp, {});
  const auto poses = fc::eye_poses(scene().camera, d);
  double gpu = 0, trace = 0, recon = 0, fit = 0, resolve = 0, cpu = 0, readback = 0, bytes = 0;
  std::uint32_t f = 0;
  for (auto _ : state) {
    const double a = 10.0 * std::sin(0.3 * f) * M_PI / 180;
    const glm::dvec3 g(std::sin(a), 0, -std::cos(a));
    const fp::FrameTimes t = p.render(poses, {g, g}, f++);
    state.SetIterationTime(t.gpu_ms() * 1e-3);
    gpu += t.gpu_ms(), trace += t.trace.gpu_ms, recon += t.reconstruct.gpu_ms, fit += t.bmfr_fit_gpu_ms;
    resolve += t.resolve.gpu_ms, cpu += t.cpu_ms();
    const fc::TimeNs t0 = fc::now_ns();
    for (fc::Eye e : {fc::Eye::Left, fc::Eye::Right}) bytes += double(p.image(e).pixels.size() * sizeof(glm::vec4));
    readback += fc::ns_to_ms(fc::now_ns() - t0);
  }
  const double n = double(state.iterations());
  state.counters["gpu_total_ms"] = gpu / n;
  state.counters["trace_ms"] = trace / n;
  state.counters["reconstruct_ms"] = recon / n;
  state.counters["bmfr_fit_ms"] = fit / n;
  state.counters["resolve_ms"] = resolve / n;
  state.counters["cpu_frame_ms"] = cpu / n;
  state.counters["readback_ms"] = readback / n;
  state.counters["readback_bytes"] = bytes / n;
  state.counters["samples_per_eye"] = double(p.traced_cells(fc::Eye::Left) + p.traced_cells(fc::Eye::Right)) / 2;
}

std::vector<std::string> displays() {
  const char* env = std::getenv("FOVEA_BENCH_DISPLAYS");
  std::vector<std::string> out;
  std::stringstream in(env && *env ? env : "small,fove0");
  for (std::string d; std::getline(in, d, ',');)
    if (!d.empty()) out.push_back(d);
  return out;
}

void register_all() {
  for (const std::string& display : displays())
    for (const auto& [name, kind] : {std::pair{"visual-polar", fc::DistributionKind::VisualPolar},
                                     std::pair{"cartesian", fc::DistributionKind::Cartesian}})
      benchmark::RegisterBenchmark(("Frame/" + display + "/" + name).c_str(),
                                   [=](benchmark::State& st) { frame(st, display, kind); })
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond)
          ->Iterations(display == "small" || display == "tiny" ? 12 : 6);
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
