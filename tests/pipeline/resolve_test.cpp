// Resolve to the display: constant grids resolve to constants (φ wrap, ρ clamp, coverage),
// a smooth analytic image survives the round trip display -> grid -> display within 0.5 dB
// of the budget-limited ideal, wide cells take the lattice's reconstruction when asked, and
// the Cartesian raster its Gaussian filter.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "fovea/core/metrics.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "fovea/shaders/recon_grid.h"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

namespace {

// Smooth test image: a few low-frequency sinusoids (k in radians per pixel).
struct Wave {
  double kx, ky, phase, amp;
};
constexpr Wave kWaves[] = {{0.031, 0.012, 0.3, 0.2}, {-0.017, 0.041, 1.1, 0.15}, {0.052, -0.023, 2.0, 0.1}};

double analytic(glm::dvec2 p, double sigma) {
  double v = 0.5;
  for (const Wave& w : kWaves)
    v += w.amp * std::exp(-0.5 * (w.kx * w.kx + w.ky * w.ky) * sigma * sigma) *
         std::sin(w.kx * p.x + w.ky * p.y + w.phase);
  return v;
}

class Resolve : public GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    scene_ = renderer::load_scene("cornell");
    gs_ = std::make_unique<renderer::GpuScene>(ctx(), scene_);
  }
  renderer::Scene scene_;
  std::unique_ptr<renderer::GpuScene> gs_;
};

std::vector<glm::vec4> grid_of(const core::SampleDistribution& d, double (*f)(glm::dvec2, double)) {
  std::vector<glm::vec4> g(std::size_t(d.padded_columns()) * d.padded_rows(), glm::vec4(0));
  for (int r = 0; r < d.padded_rows(); ++r)
    for (int c = 0; c < d.padded_columns(); ++c) {
      const auto s = d.sample_at(c, r, {0, 0});
      if (s.flags & (fovea::shaders::kCellClipped | fovea::shaders::kCellPadding)) continue;
      const float v = float(f({s.screen_x, s.screen_y}, 0.0));
      g[std::size_t(r) * d.padded_columns() + c] = {v, v, v, 1};
    }
  return g;
}

}  // namespace

TEST_F(Resolve, ConstantGridResolvesToTheConstantEverywhere) {
  const core::DisplayPreset display = fovea::test::display_of_size(96, 108);
  reconstruct::ReconSettings s;
  s.blur = false;
  pipeline::FramePipeline p(ctx(), *gs_, core::stereo_views(display), {}, s, {}, true);
  const auto& d = p.distribution(core::Eye::Left);
  const core::Image img = pipeline::testing::resolve_grid(p, core::Eye::Left, grid_of(d, [](glm::dvec2, double) { return 0.75; }), false);
  for (const auto& px : img.pixels) ASSERT_NEAR(px.x, 0.75f, 1e-5f);
}

// The ideal: the image low-passed at the grid's local sample spacing h (Gaussian σ = h/2),
// i.e. what any reconstruction from samples that sparse can keep; with the lattice's
// reconstruction (on by default) the ideal of a kernel as wide as the cubic B-spline, whose
// variance is a third of a cell's squared width (σ = h/√3; the tent's is a sixth): it gives
// up detail for a lattice that does not show.
TEST_F(Resolve, RoundTripWithinHalfDecibelOfTheBudgetLimitedIdeal) {
  const core::DisplayPreset display = core::load_display("small");
  for (const bool lattice : {false, true}) {
    reconstruct::ReconSettings s;
    s.blur = false;
    s.lattice_blur = lattice;
    pipeline::FramePipeline p(ctx(), *gs_, core::stereo_views(display), {}, s, {}, true);
    const auto& d = p.distribution(core::Eye::Left);
    const core::Image img = pipeline::testing::resolve_grid(p, core::Eye::Left, grid_of(d, analytic), false);
    const double sigma_cells = lattice ? 1 / std::sqrt(3.0) : 0.5;
    core::Image truth(display.width, display.height), ideal = truth;
    for (int y = 0; y < display.height; ++y)
      for (int x = 0; x < display.width; ++x) {
        const glm::dvec2 px{x + 0.5, y + 0.5};
        const double spp = d.samples_per_pixel(px);
        const double h = spp > 0 ? std::max(1.0, 1.0 / std::sqrt(spp)) : 1.0;
        const float t = float(analytic(px, 0)), i = float(analytic(px, sigma_cells * h));
        truth.at(x, y) = {t, t, t, 1};
        ideal.at(x, y) = {i, i, i, 1};
      }
    const double got = core::psnr(img, truth), best = core::psnr(ideal, truth);
    std::printf("lattice blur %s: round trip %.2f dB, ideal %.2f dB\n", lattice ? "on" : "off", got, best);
    EXPECT_GE(got, best - 0.5) << (lattice ? "B-spline" : "tent");
  }
}

// The lattice's reconstruction (ReconSettings::lattice_blur, the `lattice-blur` option): where
// a polar cell spans kReconLatticeFullPx display pixels or more across and along the rings,
// the resample weighs the cells around a pixel with the cubic B-spline B(x)·B(y) (x across
// the rings in columns, y along them in rows of the cell's own column) instead of the tent
// T(x)·T(y), whose kinks at the cell centres draw the lattice; where the cells are under
// kReconLatticeFromPx pixels it leaves the image as it was. A single bright cell amid dark
// ones shows the kernel directly: each pixel's value is its weight.
TEST_F(Resolve, LatticeBlurReconstructsWideCellsWithTheCubicBSpline) {
  const core::DisplayPreset display = core::load_display("small");
  const auto bspline = [](double x) {
    x = std::abs(x);
    return x < 1 ? (4 - 6 * x * x + 3 * x * x * x) / 6 : x < 2 ? (2 - x) * (2 - x) * (2 - x) / 6 : 0.0;
  };
  const auto tent = [](double x) { return std::max(0.0, 1 - std::abs(x)); };
  for (const double budget : {0.01, 0.39}) {
    core::DistributionParams dp;
    dp.budget = budget;
    std::vector<core::Image> images, holes;
    for (const bool lattice : {false, true}) {
      reconstruct::ReconSettings s;
      s.blur = false;
      s.lattice_blur = lattice;
      pipeline::FramePipeline p(ctx(), *gs_, core::stereo_views(display), dp, s, {}, true);
      const core::SampleDistribution& d = p.distribution(core::Eye::Left);
      const auto& table = d.column_table();
      const core::View v = p.view(core::Eye::Left);
      // Pixels per degree: fewest at the raster's centre, at most 1 % more within 5° of it.
      const glm::dvec2 mid(v.width() / 2.0, v.height() / 2.0);
      const auto ppd = [&](glm::dvec2 step) {
        return 1 / core::angle_deg(v.pixel_to_dir(mid), v.pixel_to_dir(mid + step));
      };
      const double fewest = std::min(ppd({1, 0}), ppd({0, 1})), most = 1.01 * std::max(ppd({1, 0}), ppd({0, 1}));
      // A column's cells in pixels, the smaller and the larger extent (rows at its inner edge).
      const auto extent = [&](int c, double px_per_deg) {
        const auto& col = table[std::size_t(c)];
        const double row = 360 * std::sin(double(col.r0) * std::numbers::pi / 180) / col.rows;
        const double w = double(col.r1 - col.r0);
        return std::pair{std::min(w, row) * px_per_deg, std::max(w, row) * px_per_deg};
      };
      // The impulse's column: its neighbours within two columns full rings with cells of more than
      // kReconLatticeFullPx pixels (budget 0.01), or within 5° of the gaze with cells under
      // kReconLatticeFromPx (0.39: the fovea's cells, about a pixel at the cap).
      const double from = fovea::shaders::kReconLatticeFromPx, full = fovea::shaders::kReconLatticeFullPx;
      int c = -1;
      for (int k = 2; c < 0 && k + 2 < d.columns(); ++k) {
        bool ok = true;
        for (int j = k - 2; j <= k + 2; ++j)
          ok = ok && (budget < 0.1 ? table[std::size_t(j)].phi_gap == 0 && extent(j, fewest).first > full + 0.1
                                   : table[std::size_t(j)].r1 < 5 && extent(j, most).second < from - 0.05);
        if (ok) c = k;
      }
      ASSERT_GE(c, 0) << budget;
      const int pcols = d.padded_columns(), rows = int(table[std::size_t(c)].rows), r0 = rows / 3;
      std::vector<glm::vec4> grid(std::size_t(pcols) * d.padded_rows(), glm::vec4(0));
      for (int cc = 0; cc < d.columns(); ++cc)
        for (int r = 0; r < int(table[std::size_t(cc)].rows); ++r) grid[std::size_t(r) * pcols + cc] = {0, 0, 0, 1};
      grid[std::size_t(r0) * pcols + c] = {1, 0, 0, 1};
      images.push_back(pipeline::testing::resolve_grid(p, core::Eye::Left, grid, false));
      if (budget > 0.1) continue;
      // Every pixel against the kernel at its grid coordinate (u across columns, cell centres
      // at +0.5; t·rows along the full ring, wrapping).
      const std::vector<glm::vec4> uv = pipeline::testing::resolve_grid_coords(p, core::Eye::Left);
      double worst = 0, peak = 0, reach = 0;
      for (int y = 0; y < v.height(); ++y)
        for (int x = 0; x < v.width(); ++x) {
          const glm::vec4 g = uv[std::size_t(y) * v.width() + x];
          const double du = g.x - (c + 0.5), dv = std::remainder(double(g.y) * rows - (r0 + 0.5), double(rows));
          const double want = lattice ? bspline(du) * bspline(dv) : tent(du) * tent(dv);
          const double got = images.back().at(x, y).x;
          if (want > 0) {
            ASSERT_EQ(g.z, 0.0f) << "level 0 at pixel " << x << ", " << y;
          }
          worst = std::max(worst, std::abs(got - want));
          peak = std::max(peak, got);
          if (got > 1e-4) reach = std::max(reach, std::abs(du));
        }
      std::printf("budget %.2f, column %d (%.1f-%.1f px), lattice blur %s: peak %.3f, reach %.2f columns, worst %.1e\n",
                  budget, c, extent(c, fewest).first, extent(c, fewest).second, lattice ? "on" : "off", peak, reach,
                  worst);
      EXPECT_LT(worst, 2e-3) << (lattice ? "B-spline" : "tent");
      EXPECT_NEAR(reach, lattice ? 2.0 : 1.0, 0.25);
      // Two columns without a sample (as under the lens) amid lit ones: the pixels between
      // their centres stay without one, however far the spline reaches.
      for (int cc = 0; cc < d.columns(); ++cc)
        for (int r = 0; r < int(table[std::size_t(cc)].rows); ++r)
          grid[std::size_t(r) * pcols + cc] = cc == c + 1 || cc == c + 2 ? glm::vec4(0) : glm::vec4(1, 1, 1, 1);
      holes.push_back(pipeline::testing::resolve_grid(p, core::Eye::Left, grid, false));
    }
    if (budget > 0.1) {  // cells under a pixel: the tent, as without the option
      EXPECT_EQ(images[0].pixels, images[1].pixels);
    } else {
      long unlit = 0;
      for (std::size_t i = 0; i < holes[0].pixels.size(); ++i) {
        unlit += holes[0].pixels[i].x == 0;
        ASSERT_EQ(holes[0].pixels[i].x == 0, holes[1].pixels[i].x == 0) << "pixel " << i;
      }
      EXPECT_GT(unlit, 100);
    }
  }
}

// The Cartesian raster's reconstruction filter (ReconSettings::raster_gaussian, the
// `raster-filter` option): box, each display pixel shows its own cell; gaussian, the cells
// around it weighed per axis by s, 1 − 2s, s (s = raster_filter_side_weight, pbrt-v4's
// Gaussian of σ = 0.5 px cut at 1.5 px), renormalised at the raster's border. Single bright
// cells amid dark ones, inside and at a corner, show the kernel; a pixel whose own cell holds
// no sample stays without one.
TEST_F(Resolve, RasterFilterWeighsTheNeighbouringCellsWithPbrtsGaussian) {
  const double side = reconstruct::raster_filter_side_weight();
  EXPECT_NEAR(side, 0.1004, 5e-4);
  const core::DisplayPreset display = fovea::test::display_of_size(24, 20);
  core::DistributionParams dp;
  dp.kind = core::DistributionKind::Cartesian;
  dp.budget = 1;
  for (const bool gaussian : {false, true}) {
    reconstruct::ReconSettings s;
    s.blur = false;
    s.raster_gaussian = gaussian;
    pipeline::FramePipeline p(ctx(), *gs_, core::stereo_views(display), dp, s, {}, true);
    const core::SampleDistribution& d = p.distribution(core::Eye::Left);
    ASSERT_EQ(d.columns(), 24);
    ASSERT_EQ(d.rows(), 20);
    const int pcols = d.padded_columns();
    std::vector<glm::vec4> grid(std::size_t(pcols) * d.padded_rows(), glm::vec4(0));
    for (int r = 0; r < 20; ++r)
      for (int c = 0; c < 24; ++c) grid[std::size_t(r) * pcols + c] = {0, 0, 0, 1};
    grid[std::size_t(7) * pcols + 9] = {1, 0, 0, 1};  // inside
    grid[0] = {1, 0, 0, 1};                           // the corner
    grid[std::size_t(15) * pcols + 15] = glm::vec4(0);  // no sample
    grid[std::size_t(15) * pcols + 16] = {1, 1, 1, 1};  // next to it
    const core::Image img = pipeline::testing::resolve_grid(p, core::Eye::Left, grid, false);
    const auto w = [&](int k) {
      if (!gaussian) return k == 0 ? 1.0 : 0.0;
      return k == 0 ? 1 - 2 * side : std::abs(k) == 1 ? side : 0.0;
    };
    for (int y = 2; y < 13; ++y)
      for (int x = 4; x < 15; ++x)
        ASSERT_NEAR(img.at(x, y).x, w(x - 9) * w(y - 7), 1e-5)
            << "pixel " << x << ", " << y << (gaussian ? " gaussian" : " box");
    const double corner = gaussian ? (1 - 2 * side) * (1 - 2 * side) / ((1 - side) * (1 - side)) : 1.0;
    EXPECT_NEAR(img.at(0, 0).x, corner, 1e-5);
    EXPECT_NEAR(img.at(1, 1).x, gaussian ? side * side : 0.0, 1e-5);  // all its cells on the raster
    EXPECT_EQ(img.at(15, 15), glm::vec4(0, 0, 0, 1)) << "no sample: no colour";
    // Beside it: the weights of the cells with a sample renormalise.
    const double beside = (1 - 2 * side) * (1 - 2 * side) / (1 - side * (1 - 2 * side));
    EXPECT_NEAR(img.at(16, 15).y, gaussian ? beside : 1.0, 1e-5);
  }
}
