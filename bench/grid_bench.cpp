// Per-frame CPU grid build of the angular Visual-Polar distribution (one eye): the σ0
// solve and the column table that `SampleDistribution::set_frame` rebuilds before every
// GPU submission. One benchmark per display preset and gaze motion:
//   pursuit  the gaze follows a 15° circle around the view centre at 0.3° per frame
//            (27°/s at 90 Hz, smooth pursuit speed), so consecutive frames are close;
//   saccade  every frame jumps to another pseudo-random gaze inside the view (fixed seed),
//            the worst case for a solve that starts from the previous frame.
// Each also with the reference σ0 solver (…/bisection: the 56-step bisection the secant
// replaced), so one run gives the ratio; `evaluations` counts column marches per frame.
// Each pursuit also under the lens' hidden area (…/secant/lens), as `fovea render` culls: the
// budget's per-column estimate then probes the mask.
// Then the radius -> column lookup table the reconstruction builds from each column table,
// three per eye and frame (reconstruct::radius_lut; radius_lut/PRESET, gaze at the centre).
//   fovea_bench_grid [--benchmark_filter=fove0]
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/core/visual_polar_testing.hpp"
#include "fovea/reconstruct/grid_map.hpp"

namespace fc = fovea::core;

namespace {

std::vector<glm::dvec3> pursuit_path(const fc::View& v) {
  const glm::dvec3 c = v.centre_dir();
  glm::dvec3 b1, b2;
  fc::orthonormal_basis(c, b1, b2);
  constexpr double kDeg = std::numbers::pi / 180;
  constexpr double kRadius = 15 * kDeg, kStep = 0.3 * kDeg;
  const int n = int(2 * std::numbers::pi * kRadius / kStep);
  std::vector<glm::dvec3> path;
  for (int i = 0; i < n; ++i) {
    const double phi = 2 * std::numbers::pi * i / n;
    path.push_back(std::cos(kRadius) * c + std::sin(kRadius) * (std::cos(phi) * b1 + std::sin(phi) * b2));
  }
  return path;
}

std::vector<glm::dvec3> saccade_path(const fc::View& v) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  std::vector<glm::dvec3> path;
  for (int i = 0; i < 64; ++i) path.push_back(v.pixel_to_dir({u(rng) * v.width(), u(rng) * v.height()}));
  return path;
}

void grid_build(benchmark::State& state, const std::string& preset, bool saccades, bool bisection, bool lens) {
  const fc::DisplayPreset display = fc::load_display(preset);
  const fc::View view = display.view(fc::Eye::Left);
  // The lens' hidden area given when the grid is laid out, as `fovea render` gives it.
  const std::optional<fc::ViewMask> mask =
      lens ? std::optional(fc::EyeOptics(display, fc::Eye::Left).view_mask()) : std::nullopt;
  const auto dist = fc::make_distribution(view, fc::DistributionParams{}, mask ? &*mask : nullptr);
  fc::set_reference_sigma0_solve(*dist, bisection);
  const auto path = saccades ? saccade_path(view) : pursuit_path(view);
  std::size_t i = 0;
  double evaluations = 0;
  for (auto _ : state) {
    dist->set_frame(path[i], std::uint32_t(i));
    benchmark::DoNotOptimize(dist->column_table().data());
    evaluations += fc::visual_polar_state(*dist)->evaluations;
    i = (i + 1) % path.size();
  }
  state.counters["columns"] = dist->columns();
  state.counters["rows"] = dist->rows();
  state.counters["evaluations"] = evaluations / double(state.iterations());
}

void radius_lut(benchmark::State& state, const std::string& preset) {
  const fc::View view = fc::load_display(preset).view(fc::Eye::Left);
  const auto dist = fc::make_distribution(view, fc::DistributionParams{});
  dist->set_frame(view.centre_dir());
  for (auto _ : state) benchmark::DoNotOptimize(fovea::reconstruct::radius_lut(dist->column_table()).entries.data());
  state.counters["columns"] = dist->columns();
}

}  // namespace

int main(int argc, char** argv) {
  for (const std::string& preset : fc::display_preset_names())
    for (const bool saccades : {false, true})
      for (const bool bisection : {false, true})
        benchmark::RegisterBenchmark(("grid_build/" + preset + (saccades ? "/saccade" : "/pursuit") +
                                      (bisection ? "/bisection" : "/secant"))
                                         .c_str(),
                                     grid_build, preset, saccades, bisection, false)
            ->Unit(benchmark::kMicrosecond);
  for (const std::string& preset : fc::display_preset_names())
    benchmark::RegisterBenchmark(("grid_build/" + preset + "/pursuit/secant/lens").c_str(), grid_build, preset, false,
                                 false, true)
        ->Unit(benchmark::kMicrosecond);
  for (const std::string& preset : fc::display_preset_names())
    benchmark::RegisterBenchmark(("radius_lut/" + preset).c_str(), radius_lut, preset)->Unit(benchmark::kMicrosecond);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
