// BMFR at 1280×720 per eye, the resolution of the BMFR paper's timings (PoCL reference:
// ~480 ms per frame on 2 cores).
// - fit: the fit (shaders/recon_bmfr_fit.comp) alone on a synthetic grid, one eye, inputs
//   resident on the device; wall time of one submission holding the fit only; per schedule
//   (workgroup/subgroup: 0/0 the device's own, reconstruct::bmfr_schedule). The scene is
//   a room corner (three walls and a floor, positions in metres) with noisy radiance, so
//   every block has valid rows, several normals and rank-deficient planar parts. Counters:
//   gpu_ms (timestamps around the dispatch), cpu_ms (the process's CPU time), the schedule.
// - Chain/<scene>: the whole reconstruction before the resolve (Phase I accumulation, stereo
//   gather, fit, Phase III, TAA) of a stereo Cartesian 1280×720 frame of a shipped scene after
//   two frames of history, each pass in its own submission (pipeline/testing.hpp). The
//   benchmark's time is the GPU time of the chain per eye (timestamps, both eyes / 2);
//   counters per pass and eye: <pass>_ms (GPU) and <pass>_cpu_ms (the process's CPU time,
//   lavapipe's work, which other load inflates less than elapsed time), load1 the load average.
//   LP_NUM_THREADS=2 fovea_bench_bmfr [--benchmark_filter=...] [--benchmark_repetitions=N]
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/geometric.hpp>

#include "fovea/core/clock.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/timer.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/pipeline/testing.hpp"
#include "fovea/reconstruct/bmfr.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "fovea/shaders/pt_scene.h"

namespace fc = fovea::reconstruct;
namespace fg = fovea::gpu;
namespace fp = fovea::pipeline;

namespace {

constexpr std::uint32_t kWidth = 1280, kHeight = 720;
constexpr std::uint32_t kPadded = (kHeight + 31) / 32 * 32;

fg::Context& context() {
  static fg::Context ctx;
  return ctx;
}

double process_cpu_ms() { return fovea::core::ns_to_ms(fovea::core::process_cpu_ns()); }

double load1() {
  double l[1] = {0};
  return getloadavg(l, 1) == 1 ? l[0] : 0.0;
}

struct Inputs {
  std::vector<glm::vec4> pos, nrm, z;
};

// A pinhole view of a box from inside: each cell's ray hits the nearest of the walls
// x = ±2, y = −1.5 (floor), z = −4 (back wall).
Inputs room() {
  Inputs in;
  const std::size_t cells = std::size_t(kWidth) * kPadded;
  in.pos.assign(cells, glm::vec4(0, 0, 0, -2));  // padding rows: no sample
  in.nrm.assign(cells, glm::vec4(0));
  in.z.assign(cells, glm::vec4(0));
  std::mt19937 rng(7);
  std::exponential_distribution<float> noise(1.0f);
  for (std::uint32_t y = 0; y < kHeight; ++y)
    for (std::uint32_t x = 0; x < kWidth; ++x) {
      const glm::vec3 d((x + 0.5f) / kWidth * 2 - 1, 0.56f * (1 - (y + 0.5f) / kHeight * 2), -1.0f);
      float t = 4.0f / -d.z;
      glm::vec3 n(0, 0, 1);
      if (d.x != 0 && 2.0f / std::abs(d.x) < t) t = 2.0f / std::abs(d.x), n = glm::vec3(d.x > 0 ? -1 : 1, 0, 0);
      if (d.y < 0 && 1.5f / -d.y < t) t = 1.5f / -d.y, n = glm::vec3(0, 1, 0);
      const glm::vec3 p = t * d;
      const std::size_t i = std::size_t(y) * kWidth + x;
      in.pos[i] = glm::vec4(p, float(n.x != 0 ? 1 : 0));
      in.nrm[i] = glm::vec4(n, t);
      const float shade = 0.3f + 0.2f * std::cos(p.x) + 0.1f * p.z;
      in.z[i] = glm::vec4(glm::vec3(std::max(shade, 0.0f) * noise(rng)), 1);
    }
  return in;
}

// Arguments: workgroup invocations (0: the device's schedule, reconstruct::bmfr_schedule),
// subgroup reductions (0/1), fp16 (0/1).
void fit(benchmark::State& state) {
  fg::Context& ctx = context();
  if (state.range(1) && !ctx.info().subgroup_arithmetic) {
    state.SkipWithError("no subgroup arithmetic on this device");
    return;
  }
  const fc::BmfrSchedule schedule =
      state.range(0) ? fc::BmfrSchedule{std::uint32_t(state.range(0)),
                                        state.range(1) ? fc::BmfrReduction::Subgroup : fc::BmfrReduction::Serial}
                     : fc::bmfr_schedule(ctx.info());
  const fc::BmfrOptions options{.precision = state.range(2) ? fc::BmfrPrecision::Fp16 : fc::BmfrPrecision::Fp32,
                                .schedule = schedule};
  static const Inputs in = room();
  const std::size_t bytes = in.pos.size() * 16;
  auto make = [&](const char* name, VkFormat texels = VK_FORMAT_R32G32B32A32_SFLOAT) {  // the fit's texelFetch
    return fg::Buffer(ctx, {.size = bytes, .usage = fg::BufferUsage::Storage, .memory = fg::Memory::DeviceLocal,
                            .name = name, .texel_format = texels});
  };
  fg::Buffer p = make("bench.vpos"), n = make("bench.vnrm"), z = make("bench.z"), out = make("bench.fitted"),
             columns = make("bench.columns");  // unread: a raster grid does not wrap
  // The room's two material codes, both diffuse (white, not metallic).
  fovea::shaders::PtMaterial white{};
  white.base_r = white.base_g = white.base_b = 1.0f;
  white.texture = -1;
  const std::vector<fovea::shaders::PtMaterial> table{white, white};
  fg::Buffer materials(ctx, {.size = table.size() * sizeof(white), .usage = fg::BufferUsage::Storage,
                             .memory = fg::Memory::HostVisible, .name = "bench.materials"});
  p.upload(in.pos);
  n.upload(in.nrm);
  z.upload(in.z);
  materials.upload(table);
  const fc::BmfrFit bmfr(ctx, options);
  fg::Buffer excess = make("bench.excess"), edge = make("bench.edge", VK_FORMAT_R32_UINT);
  edge.upload(std::vector<std::uint32_t>(in.pos.size(), 0u));  // the flags come from the chain's gather: none here
  const fg::DescriptorSet set = bmfr.bind(p, n, z, out, columns, materials, excess, edge);
  std::uint32_t frame = 0;
  fg::GpuTimer timer(ctx, 1);
  std::int64_t gpu_ns = 0;
  auto run = [&] {
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      timer.begin(cmd);
      bmfr.record(cmd, set, {kWidth, kPadded}, frame, fc::bmfr_block_offset(frame), 0.01f);
      timer.stage(cmd, "fit");
    });
    if (const auto stages = timer.read()) gpu_ns += stages->front().duration_ns();
  };
  run();  // lavapipe compiles the shader at its first dispatch
  gpu_ns = 0;
  const double cpu0 = process_cpu_ms();
  for (auto _ : state) {
    run();
    ++frame;
  }
  state.counters["cpu_ms"] = (process_cpu_ms() - cpu0) / double(state.iterations());
  state.counters["gpu_ms"] = fovea::core::ns_to_ms(gpu_ns) / double(state.iterations());
  state.counters["workgroup"] = bmfr.schedule().workgroup;
  state.counters["subgroup"] = bmfr.schedule().reduction == fc::BmfrReduction::Subgroup;
  state.counters["blocks"] = double((kWidth / 32 + 1) * (kPadded / 32 + 1));
  state.counters["load1"] = load1();
}

// The chain on a stereo 1280×720 Cartesian frame (fov ±50° × ±31°, no lens: every cell is
// reconstructed), gaze straight ahead, default settings (BMFR, gather sharing).
void chain(benchmark::State& state, const char* scene_name) {
  fovea::core::DisplayPreset d;
  d.name = "hd720";
  d.width = int(kWidth);
  d.height = int(kHeight);
  d.fov_left = fovea::core::Fov::from_degrees(-50, 50, 31, -31);
  d.fov_right = d.fov_left.mirrored();
  const fovea::renderer::Scene scene = fovea::renderer::load_scene(scene_name);
  const fovea::renderer::GpuScene gpu_scene(context(), scene);
  fovea::core::DistributionParams dp;
  dp.kind = fovea::core::DistributionKind::Cartesian;
  fp::FramePipeline p(context(), gpu_scene, fovea::core::stereo_views(d), dp, fc::ReconSettings{});
  const glm::dvec3 ahead(0, 0, -1);
  std::uint32_t frame = 0;
  for (; frame < 3; ++frame) p.render(fovea::core::eye_poses(scene.camera, d), {ahead, ahead}, frame);
  fp::testing::time_reconstruct(p, frame);  // compiles the kernels not yet run with history
  fp::testing::ReconKernelTimes sum;
  const auto add = [](fp::testing::KernelTime& a, const fp::testing::KernelTime& b) {
    a.gpu_ms += b.gpu_ms, a.cpu_ms += b.cpu_ms;
  };
  for (auto _ : state) {
    const fp::testing::ReconKernelTimes t = fp::testing::time_reconstruct(p, frame++);
    state.SetIterationTime((t.accumulate.gpu_ms + t.share.gpu_ms + t.fit.gpu_ms + t.post.gpu_ms + t.taa.gpu_ms) *
                           0.5e-3);
    add(sum.accumulate, t.accumulate), add(sum.share, t.share), add(sum.fit, t.fit), add(sum.post, t.post),
        add(sum.taa, t.taa);
  }
  const double per_eye = 0.5 / double(state.iterations());
  double cpu = 0;
  for (const auto& [name, k] : {std::pair{"accumulate", sum.accumulate}, std::pair{"share", sum.share},
                                std::pair{"fit", sum.fit}, std::pair{"post", sum.post}, std::pair{"taa", sum.taa}}) {
    state.counters[std::string(name) + "_ms"] = k.gpu_ms * per_eye;
    state.counters[std::string(name) + "_cpu_ms"] = k.cpu_ms * per_eye;
    cpu += k.cpu_ms * per_eye;
  }
  state.counters["chain_cpu_ms"] = cpu;
  state.counters["load1"] = load1();
}

}  // namespace

BENCHMARK(fit)
    ->ArgNames({"workgroup", "subgroup", "fp16"})
    ->Args({0, 0, 0})  // the device's own schedule
    ->ArgsProduct({{8, 16, 32, 64, 256}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

BENCHMARK_CAPTURE(chain, cornell, "cornell")->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(4);
BENCHMARK_CAPTURE(chain, default, "default")->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(4);

BENCHMARK_MAIN();
