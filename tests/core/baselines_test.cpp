// Invariants of the baseline distributions (docs/visual-polar.md §6).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "fovea/core/acuity.hpp"
#include "fovea/core/density_report.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"
#include "fovea/core/eye_optics.hpp"

using namespace fovea::core;
namespace sh = fovea::shaders;

namespace {

std::unique_ptr<SampleDistribution> make(DistributionKind k, const char* display = "small", double budget = 0.39) {
  DistributionParams p;
  p.kind = k;
  p.budget = budget;
  return make_distribution(load_display(display).view(Eye::Left), p);
}

TEST(Cartesian, OneSamplePerPixelAtPixelCentres) {
  auto d = make(DistributionKind::Cartesian);
  const View& v = d->view();
  ASSERT_EQ(d->columns(), v.width());
  ASSERT_EQ(d->rows(), v.height());
  for (int y = 0; y < v.height(); y += 7)
    for (int x = 0; x < v.width(); x += 5) {
      const auto s = d->sample_at(x, y, {0, 0});  // the cell centre (sample() adds the frame's jitter)
      EXPECT_EQ(s.flags, 0u);
      EXPECT_NEAR(s.screen_x, x + 0.5, 1e-4);
      EXPECT_NEAR(s.screen_y, y + 0.5, 1e-4);
      EXPECT_NEAR(d->samples_per_pixel({x + 0.5, y + 0.5}), 1.0, 1e-9);
    }
  const auto r = measure_density(*d);
  EXPECT_EQ(r.traced, std::int64_t(v.width()) * v.height());
  for (const auto& b : r.bands) {
    if (b.samples < 1000) continue;
    EXPECT_NEAR(b.samples_per_deg2 / b.display_pixels_per_deg2, 1.0, 0.05) << b.e_min;
  }
}

// count_cells is measure_density's count without the bands: the same four numbers for every
// kind, under the lens, at an off-centre gaze and with a row stride.
TEST(DensityReport, CountCellsIsMeasureDensitysCount) {
  const DisplayPreset display = load_display("small");
  const ViewMask mask = EyeOptics(display, Eye::Left).view_mask();
  for (DistributionKind k : {DistributionKind::Cartesian, DistributionKind::CartesianUniform, DistributionKind::VisualPolar,
                             DistributionKind::PaperVisualPolar, DistributionKind::LogPolar}) {
    auto d = make(k);
    d->set_visibility(mask);
    d->set_frame(d->view().pixel_to_dir({40, 200}));
    for (int stride : {1, 3}) {
      const CellCounts c = count_cells(*d, stride);
      const DensityReport r = measure_density(*d, 2.0, 1, stride);
      EXPECT_GT(c.traced, 0) << distribution_name(k);
      EXPECT_GT(c.hidden, 0) << distribution_name(k);
      EXPECT_EQ(c.traced, r.traced) << distribution_name(k) << " " << stride;
      EXPECT_EQ(c.hidden, r.hidden) << distribution_name(k) << " " << stride;
      EXPECT_EQ(c.offscreen, r.offscreen) << distribution_name(k) << " " << stride;
      EXPECT_EQ(c.grid_samples, r.grid_samples) << distribution_name(k) << " " << stride;
    }
  }
}

TEST(CartesianUniform, EqualBudgetAndRoundTrip) {
  for (double budget : {0.01, 0.25, 0.39, 1.0}) {
    auto d = make(DistributionKind::CartesianUniform, "fove0", budget);
    const View& v = d->view();
    const double cells = double(d->columns()) * d->rows();
    EXPECT_NEAR(cells / (double(v.width()) * v.height()), budget, 0.01 * budget + 1e-3) << budget;
    for (glm::dvec2 p : {glm::dvec2(0, 0), glm::dvec2(333.3, 1000.7), glm::dvec2(v.width(), v.height())}) {
      const auto g = d->screen_to_grid(p);
      ASSERT_TRUE(g);
      const int c = std::min(int(g->x), d->columns() - 1), r = std::min(int(g->y), d->rows() - 1);
      const auto s = d->sample_at(c, r, *g - glm::dvec2(c + 0.5, r + 0.5));
      EXPECT_NEAR(s.screen_x, p.x, 1e-3);
      EXPECT_NEAR(s.screen_y, p.y, 1e-3);
    }
  }
}

TEST(LinearFalloff, KeepProbabilityPerBandWithinThreeSigma) {
  // Weier 2016 defaults: p = 1 to 10°, linear to 0.2 at 20°, 0.2 beyond. Measured over
  // several frames (the random killing changes per frame), per 2° band against the mean p.
  auto d = make(DistributionKind::LinearFalloff, "fove0");
  const View& v = d->view();
  EXPECT_TRUE(d->invertible());  // the raster; killed cells are holes
  struct Acc {
    double kept = 0, n = 0, p_sum = 0, var_sum = 0;
  };
  std::vector<Acc> bands(64);
  for (std::uint32_t frame = 0; frame < 3; ++frame) {
    d->set_frame(v.pixel_to_dir({0.4 * v.width(), 0.55 * v.height()}), frame);
    for (int y = 0; y < v.height(); y += 2)
      for (int x = 0; x < v.width(); x += 2) {
        const auto s = d->sample(x, y);
        const double e = s.ecc_deg;
        const double p = d->samples_per_pixel({x + 0.5, y + 0.5});
        auto& a = bands[std::min(size_t(e / 2), bands.size() - 1)];
        a.kept += (s.flags & sh::kCellKilled) ? 0 : 1;
        a.n += 1;
        a.p_sum += p;
        a.var_sum += p * (1 - p);
      }
  }
  int checked = 0;
  for (size_t b = 0; b < bands.size(); ++b) {
    const auto& a = bands[b];
    if (a.n < 100) continue;
    ++checked;
    const double sigma = std::sqrt(std::max(a.var_sum, 1e-12));
    EXPECT_LE(std::abs(a.kept - a.p_sum), 3 * sigma + 1e-9) << "band " << 2 * b << "-" << 2 * b + 2;
  }
  EXPECT_GT(checked, 20);
  // The fovea is never killed; the periphery keeps Pp.
  EXPECT_EQ(bands[0].kept, bands[0].n);
}

TEST(LinearFalloff, KillingIsDeterministicPerFrameAndSeed) {
  auto a = make(DistributionKind::LinearFalloff);
  auto b = make(DistributionKind::LinearFalloff);
  a->set_frame(a->view().centre_dir(), 7);
  b->set_frame(b->view().centre_dir(), 7);
  int differ_next_frame = 0;
  for (int y = 0; y < a->rows(); y += 3)
    for (int x = 0; x < a->columns(); x += 3) ASSERT_EQ(a->sample(x, y).flags, b->sample(x, y).flags);
  b->set_frame(b->view().centre_dir(), 8);
  for (int y = 0; y < a->rows(); y += 3)
    for (int x = 0; x < a->columns(); x += 3) differ_next_frame += a->sample(x, y).flags != b->sample(x, y).flags;
  EXPECT_GT(differ_next_frame, 100);
}

class ScreenPolarRoundTrip : public ::testing::TestWithParam<DistributionKind> {};

TEST_P(ScreenPolarRoundTrip, ScreenToGridToScreen) {
  auto d = make(GetParam(), "fove0");
  const View& v = d->view();
  for (glm::dvec2 gz : {glm::dvec2(0.5, 0.5), glm::dvec2(0, 0), glm::dvec2(0.8, 0.3), glm::dvec2(1, 1)}) {
    d->set_frame(v.pixel_to_dir({gz.x * v.width(), gz.y * v.height()}));
    double worst = 0;
    for (int k = 0; k <= 32; ++k)
      for (int l = 0; l <= 32; ++l) {
        const glm::dvec2 p{v.width() * k / 32.0, v.height() * l / 32.0};
        const auto g = d->screen_to_grid(p);
        ASSERT_TRUE(g);
        const int c = std::clamp(int(g->x), 0, d->columns() - 1);
        const int r = int(std::floor(g->y));
        const auto s = d->sample_at(c, r, *g - glm::dvec2(c + 0.5, r + 0.5));
        worst = std::max(worst, glm::length(glm::dvec2(s.screen_x, s.screen_y) - p));
      }
    EXPECT_LT(worst, 0.01) << "gaze " << gz.x << "," << gz.y;
  }
}

INSTANTIATE_TEST_SUITE_P(Kinds, ScreenPolarRoundTrip,
                         ::testing::Values(DistributionKind::PaperVisualPolar, DistributionKind::LogPolar),
                         [](const auto& i) { return i.param == DistributionKind::LogPolar ? "log_polar" : "paper_visual_polar"; });

TEST(PaperVisualPolar, ReproducesThePaperGrid) {
  // P5: 1280×1440 -> 853×960 at 2/3 per axis; the fovea clip removes 12%; ~39% of the
  // display's pixels are grid samples (full rings: as published, without visible arcs).
  DistributionParams p;
  p.kind = DistributionKind::PaperVisualPolar;
  p.pack = false;
  auto d = make_distribution(load_display("fove0").view(Eye::Left), p);
  EXPECT_NEAR(d->columns(), 853, 3);
  EXPECT_NEAR(d->rows(), 960, 3);
  std::int64_t cells = 0;
  for (const auto& c : d->column_table()) cells += c.rows;
  EXPECT_NEAR(1.0 - double(cells) / (double(d->columns()) * d->rows()), 0.12, 0.005);
  EXPECT_NEAR(double(cells) / (1280.0 * 1440.0), 0.39, 0.005);
  // The fovea edge maps to 5.79° of the 80° CDF range; the last column reaches the corner.
  const auto& t = d->column_table();
  EXPECT_GT(t.back().r1, 0.99 * std::hypot(640.0, 720.0));
}

TEST(LogPolar, KernelParametersAndCentreSpike) {
  auto d = make(DistributionKind::LogPolar, "fove0");
  // Meng's buffer (W/σ)×(H/σ) with σ = 1/√budget: the budget's fraction of the pixels.
  EXPECT_EQ(d->columns(), int(std::lround(1280 * std::sqrt(0.39))));
  EXPECT_EQ(d->rows(), int(std::lround(1440 * std::sqrt(0.39))));
  const View& v = d->view();
  const glm::dvec2 c{v.width() / 2.0, v.height() / 2.0};
  // Log-polar puts orders of magnitude more samples at the gaze than in the periphery (P5 Fig. 8).
  EXPECT_GT(d->samples_per_pixel(c + glm::dvec2(1.5, 0)) / d->samples_per_pixel(c + glm::dvec2(500, 0)), 100.0);
}

TEST(Distributions, NamesRoundTripAndUnknownRefused) {
  for (auto k : {DistributionKind::VisualPolar, DistributionKind::PaperVisualPolar, DistributionKind::Cartesian,
                 DistributionKind::CartesianUniform, DistributionKind::LinearFalloff, DistributionKind::LogPolar})
    EXPECT_EQ(parse_distribution(distribution_name(k)), k);
  EXPECT_ANY_THROW(parse_distribution("polar"));
}

TEST(Distributions, EveryKindSurvivesExtremeGazes) {
  for (auto k : {DistributionKind::VisualPolar, DistributionKind::PaperVisualPolar, DistributionKind::Cartesian,
                 DistributionKind::CartesianUniform, DistributionKind::LinearFalloff, DistributionKind::LogPolar}) {
    auto d = make(k, "tiny");
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (glm::dvec3 g : {glm::dvec3(nan), glm::dvec3(0), glm::dvec3(0, 0, 1), glm::dvec3(5, 5, -1), glm::dvec3(1e300, 0, -1)}) {
      d->set_frame(g);
      for (int y = 0; y < d->padded_rows(); ++y)
        for (int x = 0; x < d->padded_columns(); ++x) {
          const auto s = d->sample(x, y);
          ASSERT_TRUE(std::isfinite(s.dir_x) && std::isfinite(s.screen_x) && std::isfinite(s.screen_y) &&
                      std::isfinite(s.ecc_deg) && std::isfinite(s.footprint))
              << distribution_name(k);
        }
    }
  }
}

}  // namespace
