// Where a foveated frame's trace and reconstruction time goes, per sample distribution
// (docs/reconstruction-history.md, "Whole frame on fove0"): the `default` scene on a display preset
// with the lens' hidden area skipped, gaze at the centre, both eyes, the default
// reconstruction with stereo gather. Per configuration and trace order (grid: cell n in
// invocation n; tiles: pt_order.h; live: the grid pass's live tiles) it prints the grid's
// cells and traced cells, and how the path tracer's invocations fall into SIMD vectors of LANES lanes: vectors with a traced cell
// ("busy"), those among them that also hold skipped cells ("mixed": a SIMD device such as
// lavapipe pays a vector's slowest lane for all its lanes), and the mean diagonal of the
// display box a busy vector's samples span (how far apart the rays it traces in lockstep
// start). Then per round and configuration the third frame's GPU ms: trace, the trace
// again alone in the order the pipeline picks (live: the grid pass's live cells, docs/renderer.md
// "Live cells") and in the other one (every cell; testing::time_trace,
// GPU and process CPU ms), the reconstruction kernels (timed again one submission each,
// testing::time_reconstruct) with each one's process CPU / GPU time (how many of lavapipe's
// threads were busy on average: 2 for a dispatch split evenly), resolve and frame, and the
// trace ms per 1000 traced samples; last, the same frames in a pipeline that dispatches every
// cell (the other order; the reconstruction's per-cell kernels over all cells) and in one
// with the reconstruction over the live tiles too (a GPU's default; a CPU device's is every
// cell): their trace, reconstruction and frame GPU ms.
// Rounds interleave the configurations, so load on a shared machine spreads over all of
// them; compare configurations within a round.
//   fovea_bench_trace_cost [DISPLAY [ROUNDS [LANES]]]     defaults: fove0 1 8
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include "fovea/core/display.hpp"
#include "fovea/core/duration.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/pipeline/testing.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "fovea/shaders/pt_order.h"

namespace fc = fovea::core;
namespace fp = fovea::pipeline;
namespace fr = fovea::renderer;

namespace {

struct Config {
  fc::DistributionKind kind;
  double budget;  // 0: the distribution's default
  std::string name() const {
    std::string n = fc::distribution_name(kind);
    if (budget > 0) n += " " + std::to_string(budget).substr(0, 4);
    return n;
  }
};

constexpr std::uint32_t kTimedFrame = 2;  // frames 0 and 1 before it

struct Vectors {
  long busy = 0, mixed = 0;
  double extent_px = 0;  // mean over the busy vectors
};

// `columns`: the grid's padded column count, for the tile order; `live`: the live order's list.
Vectors vectors(const std::vector<fovea::shaders::GridSample>& grid, std::size_t lanes, fr::TraceOrder order,
                std::uint32_t columns, const std::vector<std::uint32_t>& live) {
  Vectors v;
  double extent = 0;
  const std::uint32_t cells = std::uint32_t(grid.size());
  const std::size_t invocations = order == fr::TraceOrder::Live ? live.size() : grid.size();
  for (std::size_t start = 0; start < invocations; start += lanes) {
    glm::vec2 lo(1e30f), hi(-1e30f);
    int traced = 0, n = 0;
    for (std::size_t i = start; i < std::min(invocations, start + lanes); ++i, ++n) {
      std::size_t cell = i;
      if (order == fr::TraceOrder::Live) cell = live[i];
      if (order == fr::TraceOrder::Tiles) cell = fovea::shaders::pt_tile_cell(std::uint32_t(i), columns, cells);
      const auto& g = grid[cell];
      if (g.flags != 0) continue;
      ++traced;
      lo = glm::min(lo, glm::vec2(g.screen_x, g.screen_y));
      hi = glm::max(hi, glm::vec2(g.screen_x, g.screen_y));
    }
    if (traced == 0) continue;
    ++v.busy;
    v.mixed += traced < n ? 1 : 0;
    extent += glm::length(hi - lo);
  }
  v.extent_px = v.busy ? extent / double(v.busy) : 0;
  return v;
}

// The 1-minute load average (Linux), 0 where it cannot be read: printed next to each time.
const char* order_name(fr::TraceOrder o) {
  return o == fr::TraceOrder::Live ? "live" : o == fr::TraceOrder::Tiles ? "tiles" : "grid";
}

// Process CPU time over elapsed GPU time: how many of lavapipe's threads were busy on
// average (2 when both work to the end of the dispatch).
double threads_busy(const fp::testing::KernelTime& k) { return k.gpu_ms > 0 ? k.cpu_ms / k.gpu_ms : 0; }

double load_average() {
  double load = 0;
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &load) != 1) load = 0;
    std::fclose(f);
  }
  return load;
}

long positive(const char* arg, const char* what) {
  char* end = nullptr;
  const long v = std::strtol(arg, &end, 10);
  if (!end || *end || v < 1 || v > 1000) throw fc::InputError(std::string(what) + " must be an integer in 1..1000");
  return v;
}

int run(int argc, char** argv) {
  const std::string display_name = argc > 1 ? argv[1] : "fove0";
  const long rounds = argc > 2 ? positive(argv[2], "ROUNDS") : 1;
  const long lanes = argc > 3 ? positive(argv[3], "LANES") : 8;
  const fc::DisplayPreset display = fc::load_display(display_name);
  fovea::gpu::Context ctx;
  const fr::Scene scene = fr::load_scene("default");
  const fr::GpuScene gs(ctx, scene);
  const auto poses = fc::eye_poses(scene.camera, display);
  const glm::dvec3 gaze(0, 0, -1);
  // Visual-Polar at its default budget and three lower ones; a uniform raster with as many
  // samples as Visual-Polar at the default and at the lowest (the same count, spread evenly
  // and coherently: sparsity without the polar layout); full resolution.
  const fc::DistributionParams defaults;
  const Config configs[] = {{fc::DistributionKind::VisualPolar, 0},
                            {fc::DistributionKind::VisualPolar, 0.25},
                            {fc::DistributionKind::VisualPolar, 0.2},
                            {fc::DistributionKind::VisualPolar, 0.1},
                            {fc::DistributionKind::CartesianUniform, defaults.budget},
                            {fc::DistributionKind::CartesianUniform, 0.1},
                            {fc::DistributionKind::Cartesian, 1}};
  fovea::reconstruct::ReconSettings settings;
  settings.share = fovea::reconstruct::StereoShare::Gather;
  std::printf("%s, default scene, gaze at the centre, hidden area skipped, both eyes; %s; %ld-lane vectors\n",
              display_name.c_str(), ctx.info().name.c_str(), lanes);
  std::printf("| configuration | order | cells / eye | traced / eye | busy vectors | mixed vectors | busy vector extent, px |\n"
              "|---|---|---|---|---|---|---|\n");
  std::vector<std::string> rows;
  for (long round = 0; round < rounds; ++round)
    for (const Config& c : configs) {
      fc::DistributionParams dp;
      dp.kind = c.kind;
      if (c.budget > 0) dp.budget = c.budget;
      // The lens' hidden area given when the grids are laid out, as `fovea render` gives it.
      fp::EyeMasks masks;
      for (fc::Eye e : {fc::Eye::Left, fc::Eye::Right}) masks[std::size_t(e)] = fc::EyeOptics(display, e).view_mask();
      fp::FramePipeline p(ctx, gs, fc::stereo_views(display), dp, settings, {}, false, masks);
      // Frame 0 has no history (and its dispatches compile the shaders), and the first two
      // frames reconstruct every tile (the live tiles' reset rule, docs/renderer.md "Live
      // cells"); the third is the one a running session pays. Its trace is then timed again
      // alone in both orders, twice each (ABBA, A alternating between rounds): GPU ms, and the
      // process's CPU ms, which other processes on a shared machine inflate less than elapsed time.
      for (std::uint32_t f = 0; f < kTimedFrame; ++f) p.render(poses, {gaze, gaze}, f);
      const fp::FrameTimes t = p.render(poses, {gaze, gaze}, kTimedFrame);
      const fr::TraceOrder picked = fp::testing::trace_order(p, fc::Eye::Left);
      // The other: every cell dispatched, in tile order on polar grids, grid order on rasters.
      const bool polar = p.distribution(fc::Eye::Left).gpu_params().family != fovea::shaders::kFamilyCartesian;
      const fr::TraceOrder orders[2] = {picked, polar ? fr::TraceOrder::Tiles : fr::TraceOrder::Grid};
      fp::testing::KernelTime trace[2];  // sums over the two repetitions
      const double load0 = load_average();
      for (int k = 0; k < 4; ++k) {
        const int which = ((k == 0 || k == 3) ? 0 : 1) ^ int(round % 2);
        const fp::testing::KernelTime kt = fp::testing::time_trace(p, kTimedFrame, orders[which]);
        trace[which].gpu_ms += 0.5 * kt.gpu_ms;
        trace[which].cpu_ms += 0.5 * kt.cpu_ms;
      }
      const double load1 = load_average();
      const fp::testing::ReconKernelTimes r = fp::testing::time_reconstruct(p, kTimedFrame);
      // The same frames with every cell dispatched (the other order, and the reconstruction's
      // per-cell kernels over all cells), and with the live tiles for the reconstruction too
      // (a GPU's default): what the live-tile list saves in the whole frame.
      const auto frame_in_order = [&](fr::TraceOrder order) {
        fp::FramePipeline q(ctx, gs, fc::stereo_views(display), dp, settings, {}, false, masks);
        fp::testing::set_trace_order(q, order);
        for (std::uint32_t f = 0; f < kTimedFrame; ++f) q.render(poses, {gaze, gaze}, f);
        return q.render(poses, {gaze, gaze}, kTimedFrame);
      };
      const fp::FrameTimes all = frame_in_order(orders[1]), live = frame_in_order(fr::TraceOrder::Live);
      const long long traced = p.traced_cells(fc::Eye::Left) + p.traced_cells(fc::Eye::Right);
      if (round == 0) {
        const auto grid = p.grid_samples(fc::Eye::Left);
        for (const fr::TraceOrder o : orders) {
          const auto columns = std::uint32_t(p.distribution(fc::Eye::Left).padded_columns());
          const Vectors v = vectors(grid, std::size_t(lanes), o, columns, fp::testing::live_cells(p, fc::Eye::Left));
          std::printf("| %s | %s | %zu | %lld | %ld | %ld | %.1f |\n", c.name().c_str(), order_name(o), grid.size(),
                      static_cast<long long>(p.traced_cells(fc::Eye::Left)), v.busy, v.mixed, v.extent_px);
        }
      }
      // Times to three significant digits: seconds on a CPU device, fractions of a ms on a GPU.
      const auto ms = [](double v) { return fc::fixed_significant(v); };
      const auto three = [&](double a, double b, double c) { return ms(a) + " / " + ms(b) + " / " + ms(c); };
      char head[160], ratios[96], busy[96];
      std::snprintf(head, sizeof head, "| %ld | %s | %.2f → %.2f | ", round + 1, c.name().c_str(), load0, load1);
      std::snprintf(ratios, sizeof ratios, "%.3f / %.3f", trace[1].gpu_ms / trace[0].gpu_ms,
                    trace[1].cpu_ms / trace[0].cpu_ms);
      std::snprintf(busy, sizeof busy, "%.2f / %.2f / %.2f / %.2f / %.2f", threads_busy(r.accumulate),
                    threads_busy(r.share), threads_busy(r.fit), threads_busy(r.post), threads_busy(r.taa));
      const std::string row = std::string(head) + ms(t.trace.gpu_ms) + " | " + order_name(orders[0]) + " | " +
                              ms(trace[0].gpu_ms) + " / " + ms(trace[0].cpu_ms) + " | " + order_name(orders[1]) +
                              " | " + ms(trace[1].gpu_ms) + " / " + ms(trace[1].cpu_ms) + " | " + ratios + " | " +
                              ms(r.accumulate.gpu_ms) + " | " + ms(r.share.gpu_ms) + " | " + ms(r.fit.gpu_ms) + " | " +
                              ms(r.post.gpu_ms) + " | " + ms(r.taa.gpu_ms) + " | " + busy + " | " +
                              ms(t.reconstruct.gpu_ms) + " | " + ms(t.resolve.gpu_ms) + " | " + ms(t.gpu_ms()) + " | " +
                              ms(1000.0 * t.trace.gpu_ms / double(traced)) + " | " +
                              three(all.trace.gpu_ms, all.reconstruct.gpu_ms, all.gpu_ms()) + " | " +
                              three(live.trace.gpu_ms, live.reconstruct.gpu_ms, live.gpu_ms()) + " |";
      rows.emplace_back(row);
      std::fprintf(stderr, "%s\n", row.c_str());  // progress: a round of fove0 takes minutes under load
      std::fflush(stdout);
    }
  std::printf("\nGPU ms of the third frame, both eyes; its trace again alone in the order the pipeline picks"
              " and in the other one (GPU / process CPU ms, mean of 2), the reconstruction kernels one submission each\n");
  std::printf("| round | configuration | load | trace (frame) | order picked | trace GPU / CPU | other order |"
              " trace GPU / CPU | other / picked, GPU / CPU | accumulate | share | BMFR fit | post | TAA |"
              " CPU / GPU ms, accumulate / share / fit / post / TAA |"
              " reconstruct (frame) | resolve | frame | trace ms per 1000 samples |"
              " every cell dispatched: trace / reconstruct / frame |"
              " live tiles for the reconstruction too: trace / reconstruct / frame |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& row : rows) std::printf("%s\n", row.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const fc::InputError& e) {
    std::fprintf(stderr, "fovea_bench_trace_cost: %s\n", e.what());
    return 2;
  }
}
