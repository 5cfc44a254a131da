// BMFR fit (shaders/recon_bmfr_fit.comp) on a synthetic 1280×720 grid: one eye, the
// resolution of the BMFR paper's timings, inputs resident on the device. Wall time of one
// submission holding the fit only (upload and download excluded). The scene is a room
// corner (three walls and a floor, positions in metres) with noisy radiance, so every
// block has valid rows, several normals and rank-deficient planar parts.
//   LP_NUM_THREADS=2 fovea_bench_bmfr [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/geometric.hpp>

#include "fovea/reconstruct/bmfr.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/shaders/pt_scene.h"

namespace fc = fovea::reconstruct;
namespace fg = fovea::gpu;

namespace {

constexpr std::uint32_t kWidth = 1280, kHeight = 720;
constexpr std::uint32_t kPadded = (kHeight + 31) / 32 * 32;

fg::Context& context() {
  static fg::Context ctx;
  return ctx;
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

// Arguments: workgroup invocations, fp16 (0/1).
void fit(benchmark::State& state) {
  const fc::BmfrOptions options{.precision = state.range(1) ? fc::BmfrPrecision::Fp16 : fc::BmfrPrecision::Fp32,
                                .workgroup = std::uint32_t(state.range(0))};
  fg::Context& ctx = context();
  static const Inputs in = room();
  const std::size_t bytes = in.pos.size() * 16;
  auto make = [&](const char* name) {
    return fg::Buffer(ctx, {.size = bytes, .usage = fg::BufferUsage::Storage, .memory = fg::Memory::DeviceLocal,
                            .name = name});
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
  fg::Buffer excess = make("bench.excess");
  const fg::DescriptorSet set = bmfr.bind(p, n, z, out, columns, materials, excess);
  std::uint32_t frame = 0;
  auto run = [&] {
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      bmfr.record(cmd, set, {kWidth, kPadded}, frame, fc::bmfr_block_offset(frame), 0.01f);
    });
  };
  run();  // lavapipe compiles the shader at its first dispatch
  for (auto _ : state) {
    run();
    ++frame;
  }
  state.counters["blocks"] = double((kWidth / 32 + 1) * (kPadded / 32 + 1));
}

}  // namespace

BENCHMARK(fit)
    ->ArgNames({"workgroup", "fp16"})
    ->ArgsProduct({{64, 128, 256, 512}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

BENCHMARK_MAIN();
