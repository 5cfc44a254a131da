// What one vec4 read costs, from a storage buffer or from a texel buffer (texelFetch), per
// access pattern: the measurement behind reading per-cell and scene data as texel buffers
// (docs/gpu.md, "Texel buffers"). shaders/bench_gather.comp: 2^21 invocations each sum
// `taps` vec4s of a 32 MiB buffer at neighbouring (coherent) or hashed indices near their
// own (random; 64 KiB windows, cache-resident).
// The benchmark's time is the dispatch's GPU time (timestamps); counters: ns per read
// (elapsed) and the process CPU time per read (lavapipe's threads).
//   LP_NUM_THREADS=2 fovea_bench_gather
#include <benchmark/benchmark.h>

#include <vector>

#include "fovea/core/clock.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/gpu/timer.hpp"

namespace gpu = fovea::gpu;

namespace {

constexpr std::uint32_t kCount = 1u << 21;  // 32768 workgroups of 64

gpu::Context& context() {
  static gpu::Context ctx;
  return ctx;
}

double process_cpu_ms() { return fovea::core::ns_to_ms(fovea::core::process_cpu_ns()); }

struct Push {
  std::uint32_t count, mask, taps, random;
};

void gather(benchmark::State& state) {
  const bool texel = state.range(0) != 0, random = state.range(1) != 0;
  const auto taps = std::uint32_t(state.range(2));
  gpu::Context& ctx = context();
  gpu::Buffer src(ctx, {.size = VkDeviceSize(kCount) * 16, .name = "bench.src",
                        .texel_format = VK_FORMAT_R32G32B32A32_SFLOAT});
  std::vector<float> values(std::size_t(kCount) * 4);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = float(i % 97);
  src.upload(values);
  gpu::Buffer dst(ctx, {.size = VkDeviceSize(kCount) * 16, .name = "bench.dst"});
  const gpu::ComputePipeline p(
      ctx, {.shader = "bench_gather.comp.spv",
            .sets = {{gpu::Binding::StorageBuffer, gpu::Binding::TexelBuffer, gpu::Binding::StorageBuffer}},
            .push_constant_bytes = sizeof(Push),
            .specialization = {gpu::SpecConstant::boolean(0, texel)}});
  gpu::DescriptorSet set(ctx, p.set_layout(0));
  set.bind(0, src).bind(1, src).bind(2, dst);
  gpu::GpuTimer timer(ctx, 1);
  const Push push{kCount, kCount - 1, taps, random ? 1u : 0u};
  const auto run = [&] {
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      timer.begin(cmd);
      p.run(cmd, {&set}, push, kCount);
      timer.stage(cmd, "gather");
    });
  };
  run();  // compiles the shader
  double cpu_ms = 0, gpu_ms = 0;
  for (auto _ : state) {
    const double c0 = process_cpu_ms();
    run();
    cpu_ms += process_cpu_ms() - c0;
    const auto stages = timer.read();
    const double ms = stages ? double(stages->front().duration_ns()) * 1e-6 : 0;
    gpu_ms += ms;
    state.SetIterationTime(ms * 1e-3);
  }
  const double reads = double(kCount) * taps * double(state.iterations());
  state.counters["ns_per_read"] = gpu_ms * 1e6 / reads;
  state.counters["cpu_ns_per_read"] = cpu_ms * 1e6 / reads;
}

}  // namespace

BENCHMARK(gather)
    ->ArgNames({"texel", "random", "taps"})
    ->ArgsProduct({{0, 1}, {0, 1}, {1, 8}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

BENCHMARK_MAIN();
