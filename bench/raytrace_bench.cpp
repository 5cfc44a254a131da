// Ray-tracing throughput per scene on the current Vulkan device: primary rays (closest
// hit through the BVH, Mrays/s) and full paths of the BMFR/P5 configuration (primary,
// NEE, one bounce, NEE: Msamples/s, and the trace stage's GPU ms with the scene's shader
// variant and with the full shader). With Embree 3 installed, the same primary rays are
// traced by Embree on the CPU (all hardware threads) and the ratio is printed. Both with
// the compute BVH traversal and, where the device offers them, with ray queries
// (RayQuery*; --trace rayquery).
//   fovea_bench_raytrace [--benchmark_filter=...]   env FOVEA_BENCH_DISPLAY (default small)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "fovea/core/clock.hpp"
#include "fovea/core/display.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/timer.hpp"
#include "fovea/renderer/path_tracer.hpp"
#include "fovea/renderer/raycaster.hpp"
#include "fovea/renderer/scene_io.hpp"

#ifdef FOVEA_HAVE_EMBREE
#include "embree_rays.hpp"
#endif

namespace fr = fovea::renderer;
namespace fc = fovea::core;

namespace {

const char* const kScenes[] = {"cornell", "furnace", "glossy-spheres", "stereo-occluders", "default"};

struct Fixture {
  fr::Scene scene;
  fc::View view;
  std::vector<fovea::shaders::PtRay> rays;  // the primary rays of the view, world space
};

fovea::gpu::Context& context() {
  static fovea::gpu::Context ctx;
  return ctx;
}

const Fixture& fixture(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Fixture>> cache;
  auto& f = cache[name];
  if (!f) {
    f = std::make_unique<Fixture>();
    f->scene = fr::load_scene(name);
    const char* d = std::getenv("FOVEA_BENCH_DISPLAY");
    const fc::DisplayPreset display = fc::load_display(d ? d : "small");
    f->view = display.view(fc::Eye::Left, f->scene.camera);
    const glm::dmat3 rot = glm::mat3_cast(f->view.pose().orientation);
    const glm::dvec3 o = f->view.pose().position;
    for (const auto& s : fr::cartesian_grid(f->view)) {
      const glm::dvec3 dir = glm::normalize(rot * glm::dvec3(s.dir_x, s.dir_y, s.dir_z));
      f->rays.push_back({float(o.x), float(o.y), float(o.z), 0.0f, float(dir.x), float(dir.y), float(dir.z), 1e30f});
    }
  }
  return *f;
}

std::map<std::string, double>& results() {  // "<kind>/<scene>" -> rays or samples per second
  static std::map<std::string, double> r;
  return r;
}

// CPU time of the whole process (every lavapipe and Embree thread), ns: on a machine that
// other jobs share, rays per CPU-second compare the two tracers more stably than wall time.
using fovea::core::process_cpu_ns;

// Times `run` (which traces `rays` rays) once per benchmark iteration; records rays per
// wall-clock second and per process CPU-second under `key` and "cpu:" + key.
template <class Run>
void time_rays(benchmark::State& state, double rays_per_run, const std::string& key, Run&& run) {
  double rays = 0, secs = 0;
  std::int64_t cpu_ns = 0;
  for (auto _ : state) {
    const std::int64_t c0 = process_cpu_ns();
    const auto t0 = std::chrono::steady_clock::now();
    run();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cpu_ns += process_cpu_ns() - c0;
    state.SetIterationTime(s);
    rays += rays_per_run;
    secs += s;
  }
  state.counters["Mrays/s"] = rays / secs * 1e-6;
  state.counters["Mrays/cpu_s"] = rays / (double(cpu_ns) * 1e-9) * 1e-6;
  results()[key] = rays / secs;
  results()["cpu:" + key] = rays / (double(cpu_ns) * 1e-9);
}

const char* result_key(fr::Tracing t) { return t == fr::Tracing::RayQuery ? "rayquery/" : "gpu/"; }

void BM_PrimaryRays(benchmark::State& state, const char* scene, fr::Tracing tracing) {
  const Fixture& f = fixture(scene);
  fr::GpuScene g(context(), f.scene, {}, tracing);
  fr::Raycaster rc(context(), g);
  rc.set_rays(f.rays);
  rc.trace(fr::RayQuery::Closest);  // warm-up (pipeline compilation)
  const int repeat = 4;
  time_rays(state, double(f.rays.size()) * repeat, result_key(tracing) + std::string(scene),
            [&] { rc.trace(fr::RayQuery::Closest, repeat); });
  state.counters["triangles"] = double(g.stats().triangles);
  if (g.tracing() == fr::Tracing::Compute) {
    // Which tree was kept (bvh.hpp), what it cost to build, and the sample rays' work in it
    // and in the plain SAH tree.
    state.counters["ray_guided"] = g.stats().bvh_ray_guided ? 1.0 : 0.0;
    state.counters["bvh_build_ms"] = g.stats().build_ms;
    state.counters["sample_work"] = g.stats().bvh_ray_cost;
    state.counters["sah_sample_work"] = g.stats().bvh_sah_ray_cost;
    fr::Raycaster counting(context(), g, true);
    counting.set_rays(f.rays);
    const fr::TraversalStats t = counting.traversal_stats();
    state.counters["nodes/ray"] = t.nodes;
    state.counters["tris/ray"] = t.triangles;
    state.counters["nodes/subgroup"] = t.subgroup_nodes;  // the most any ray of its subgroup visited
    state.counters["tris/subgroup"] = t.subgroup_triangles;
    // The same rays in the plain SAH tree, for comparison.
    fr::BvhOptions sah_only;
    sah_only.ray_samples = 0;
    const fr::GpuScene plain(context(), f.scene, sah_only, tracing);
    fr::Raycaster plain_counting(context(), plain, true);
    plain_counting.set_rays(f.rays);
    const fr::TraversalStats p = plain_counting.traversal_stats();
    state.counters["sah_nodes/ray"] = p.nodes;
    state.counters["sah_tris/ray"] = p.triangles;
  }
}

// full: the shader with every scene feature compiled in, else the scene's variant.
void BM_Paths(benchmark::State& state, const char* scene, fr::Tracing tracing, bool full) {
  const Fixture& f = fixture(scene);
  fr::GpuScene g(context(), f.scene, {}, tracing);
  const auto grid = fr::cartesian_grid(f.view);
  fovea::gpu::Buffer gb(context(), {grid.size() * sizeof(fovea::shaders::GridSample), fovea::gpu::BufferUsage::Storage,
                                    fovea::gpu::Memory::DeviceLocal, "bench.grid"});
  gb.upload(grid);
  const fr::PathTracer pt = full ? fr::PathTracer(context(), g, fr::SceneFeatures{}) : fr::PathTracer(context(), g);
  fr::TraceOutputs out = pt.bind(gb, std::uint32_t(grid.size()));
  fovea::gpu::GpuTimer timer(context(), 2);
  std::uint32_t frame = 0;
  auto run = [&] {
    context().submit_and_wait([&](VkCommandBuffer cmd) {
      timer.begin(cmd);
      pt.record(cmd, out, f.view, fc::Eye::Left, frame++, {});
      timer.stage(cmd, "trace");
    });
  };
  run();
  double samples = 0, secs = 0;
  std::vector<double> gpu_ms;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    run();
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(s);
    samples += double(grid.size());
    secs += s;
    if (const auto t = timer.read(); t && !t->empty()) gpu_ms.push_back(double(t->back().duration_ns()) * 1e-6);
  }
  state.counters["Msamples/s"] = samples / secs * 1e-6;
  state.counters["ms/frame"] = secs / double(state.iterations()) * 1e3;
  if (!gpu_ms.empty()) {
    std::nth_element(gpu_ms.begin(), gpu_ms.begin() + gpu_ms.size() / 2, gpu_ms.end());
    const double median = gpu_ms[gpu_ms.size() / 2];
    state.counters["trace_gpu_ms"] = median;
    if (tracing == fr::Tracing::Compute) results()[(full ? "full/" : "variant/") + std::string(scene)] = median;
  }
}

#ifdef FOVEA_HAVE_EMBREE
void BM_EmbreePrimaryRays(benchmark::State& state, const char* scene) {
  const Fixture& f = fixture(scene);
  const fovea::bench::EmbreeScene embree(f.scene);
  embree.trace(f.rays, false);
  time_rays(state, 4.0 * double(f.rays.size()), "embree/" + std::string(scene), [&] {
    for (int k = 0; k < 4; ++k) embree.trace(f.rays, false);
  });
}
#endif

}  // namespace

int main(int argc, char** argv) {
  const bool ray_query = context().features().ray_query;
  for (const char* s : kScenes) {
    benchmark::RegisterBenchmark((std::string("PrimaryRays/") + s).c_str(), BM_PrimaryRays, s, fr::Tracing::Compute)
        ->UseManualTime()
        ->MinTime(1.0);
    benchmark::RegisterBenchmark((std::string("Paths/") + s).c_str(), BM_Paths, s, fr::Tracing::Compute, false)
        ->UseManualTime()
        ->MinTime(1.0);
    benchmark::RegisterBenchmark((std::string("PathsFullShader/") + s).c_str(), BM_Paths, s, fr::Tracing::Compute,
                                 true)
        ->UseManualTime()
        ->MinTime(1.0);
    if (ray_query) {
      benchmark::RegisterBenchmark((std::string("RayQueryPrimaryRays/") + s).c_str(), BM_PrimaryRays, s,
                                   fr::Tracing::RayQuery)
          ->UseManualTime()
          ->MinTime(1.0);
      benchmark::RegisterBenchmark((std::string("RayQueryPaths/") + s).c_str(), BM_Paths, s, fr::Tracing::RayQuery,
                                   false)
          ->UseManualTime()
          ->MinTime(1.0);
    }
#ifdef FOVEA_HAVE_EMBREE
    benchmark::RegisterBenchmark((std::string("EmbreePrimaryRays/") + s).c_str(), BM_EmbreePrimaryRays, s)
        ->UseManualTime()
        ->MinTime(1.0);
#endif
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  std::printf("device: %s (%s)\n", context().info().name.c_str(), context().info().driver.c_str());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (const char* s : kScenes) {
    for (const fr::Tracing t : {fr::Tracing::Compute, fr::Tracing::RayQuery}) {
      const auto g = results().find(result_key(t) + std::string(s)), e = results().find(std::string("embree/") + s);
      if (g != results().end() && e != results().end())
        std::printf("%-18s primary rays (%s): %s %.2f Mrays/s, Embree %.2f Mrays/s, Embree/GPU = %.2fx; "
                    "per CPU-second %.2fx\n",
                    s, fr::tracing_name(t), context().info().name.c_str(), g->second * 1e-6, e->second * 1e-6,
                    e->second / g->second, results()["cpu:embree/" + std::string(s)] / results()["cpu:" + g->first]);
    }
    const auto v = results().find(std::string("variant/") + s), f = results().find(std::string("full/") + s);
    if (v != results().end() && f != results().end())
      std::printf("%-18s paths: trace stage %.1f ms with the scene's shader variant, %.1f ms with the full shader (%.2fx)\n",
                  s, v->second, f->second, f->second / v->second);
  }
  return 0;
}
