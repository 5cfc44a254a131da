// The resolve's display -> grid inverse on the GPU (float; column through the per-frame
// radius lookup table, reconstruct::radius_lut) against the CPU's exact inverse
// (core PolarDistribution::screen_to_grid: double atan2, binary search of the double
// radii) for every pixel of the `small` and `fove0` rasters, with the gaze at the centre,
// 25° off it and near a corner. u (column coordinate) is continuous across column
// boundaries, so it is compared directly: a wrong column would be off by up to a cell.
// φ is compared in rows of the pixel's column, circularly. Measured: at most 2.1e-3 cells in
// u and 8.4e-4 rows in φ (fove0), the same with the full binary search instead of the
// table: the float mapping's precision, not the lookup. Every pixel must land inside the
// grid: 0 <= u <= columns, 0 <= t <= 1.
#include <algorithm>
#include <numbers>
#include <cmath>

#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

namespace {

// Largest deviations of the GPU inverse from the CPU's over a raster.
struct InverseError {
  double u = 0, rows = 0;  // column coordinate (cells); φ in rows of the pixel's column
  long outside = 0, pixels = 0;
};

InverseError compare(const core::SampleDistribution& d, const std::vector<glm::vec4>& gpu, int width, int height) {
  InverseError err;
  const auto& table = d.column_table();
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const glm::vec4 g = gpu[std::size_t(y) * width + x];
      ++err.pixels;
      if (!(g.x >= 0 && g.x <= float(d.columns()) && g.y >= 0 && g.y <= 1)) {
        ++err.outside;
        continue;
      }
      const auto cpu = d.screen_to_grid({x + 0.5, y + 0.5});
      if (!cpu) continue;
      err.u = std::max(err.u, std::abs(double(g.x) - cpu->x));
      const int column = std::clamp(int(cpu->x), 0, d.columns() - 1);
      const auto& col = table[std::size_t(column)];
      const double rows = col.rows;
      // The GPU's coordinate is in turns of φ; the CPU's in rows from the start of the
      // column's arc (rg_row_coord; a full ring's arc is the whole turn and wraps).
      const double span = 1.0 - double(col.phi_gap) / (2.0 * std::numbers::pi);
      double t = std::fmod(double(g.y) - double(col.phi0) / (2.0 * std::numbers::pi), 1.0);
      if (t < 0) t += 1.0;
      if (t > span) t = t - span < 1.0 - t ? span : 0.0;
      const double dr = std::abs(t / span * rows - cpu->y);
      err.rows = std::max(err.rows, col.phi_gap == 0.0f ? std::min(std::fmod(dr, rows), rows - std::fmod(dr, rows)) : dr);
    }
  return err;
}

class ResolveInverse : public GpuTest, public ::testing::WithParamInterface<const char*> {};

}  // namespace

TEST_P(ResolveInverse, MatchesTheExactInverseOnEveryPixel) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene, {}, fovea::test::kStatisticsTracing);
  const core::DisplayPreset display = core::load_display(GetParam());
  reconstruct::ReconSettings s;
  s.denoiser = reconstruct::Denoiser::None;
  s.blur = false;
  renderer::PathConfig path;
  path.max_bounces = 0;
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), {}, s, path, true);
  // Centre, 25° towards the upper right, and 45° towards the lower left (near the corner at
  // fove0's 50°×53° half-FOV; its opposite corner is then > 90° from the gaze).
  const glm::dvec3 gazes[] = {{0, 0, -1}, glm::normalize(glm::dvec3(0.33, 0.33, -1)),
                              glm::normalize(glm::dvec3(-0.71, -0.71, -1))};
  std::uint32_t frame = 0;
  for (const glm::dvec3& g : gazes) {
    p.render(core::eye_poses(scene.camera, display), {g, g}, frame++);
    const core::SampleDistribution& d = p.distribution(core::Eye::Left);
    const InverseError e =
        compare(d, pipeline::testing::resolve_grid_coords(p, core::Eye::Left), display.width, display.height);
    std::printf("%s gaze (%.2f, %.2f, %.2f): %ld pixels, %d columns, max |du| %.2e cells, max |dphi| %.2e rows\n",
                GetParam(), g.x, g.y, g.z, e.pixels, d.columns(), e.u, e.rows);
    EXPECT_EQ(e.outside, 0);
    EXPECT_LT(e.u, 5e-3);
    EXPECT_LT(e.rows, 5e-3);
  }
}

INSTANTIATE_TEST_SUITE_P(Displays, ResolveInverse, ::testing::Values("small", "fove0"));
