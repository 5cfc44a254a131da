// GPU grid generation (shaders/grid_generate.comp) = the CPU double-precision reference
// (core::SampleDistribution::sample) for every distribution, on lavapipe.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <numeric>
#include <vector>

#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/grid_pass.hpp"
#include "fovea/shaders/live_cells.h"
#include "fovea/shaders/pt_order.h"
#include "gpu_fixture.hpp"

using namespace fovea;
using fovea::test::GpuTest;

namespace {

struct Case {
  const char* display;
  core::DistributionKind kind;
};

class GridPassTest : public GpuTest, public ::testing::WithParamInterface<Case> {};

TEST_P(GridPassTest, MatchesCpuReference) {
  const Case c = GetParam();
  const core::View view = core::load_display(c.display).view(core::Eye::Left);
  core::DistributionParams p;
  p.kind = c.kind;
  auto d = core::make_distribution(view, p);
  d->set_jitter(true);
  gpu::GridPass pass(ctx());
  const glm::dvec2 gazes[] = {{0.5, 0.5}, {0.2, 0.7}, {0, 0}, {1, 0.5}, {0.5 + 0.5 / view.width(), 0.5}};
  double worst_px = 0, worst_dir = 0;
  for (std::uint32_t f = 0; f < std::size(gazes); ++f) {
    d->set_frame(view.pixel_to_dir({gazes[f].x * view.width(), gazes[f].y * view.height()}), f);
    gpu::Buffer out(ctx(), {.size = gpu::GridPass::samples_bytes(*d), .memory = gpu::Memory::HostVisible,
                            .name = "grid samples"});
    pass.generate(*d, out);
    const auto got = out.download<shaders::GridSample>();
    int flag_mismatch = 0;
    for (int row = 0; row < d->padded_rows(); ++row)
      for (int col = 0; col < d->padded_columns(); ++col) {
        const auto& g = got[size_t(row) * d->padded_columns() + col];
        const auto r = d->sample(col, row);
        ASSERT_TRUE(std::isfinite(g.dir_x) && std::isfinite(g.dir_y) && std::isfinite(g.dir_z) &&
                    std::isfinite(g.screen_x) && std::isfinite(g.screen_y) && std::isfinite(g.ecc_deg) &&
                    std::isfinite(g.footprint));
        // A clipped cell is never traced: only its clipped bit matters (a packed column's
        // clipped rows map far beyond its arc, where a float φ is coarse).
        if ((r.flags & shaders::kCellClipped) && (g.flags & shaders::kCellClipped)) continue;
        if (g.flags != r.flags) {
          // Only cells within float rounding of a decision boundary may differ: the display
          // edge (the cell centre's, kCellEdgeTolPx outside), or a linear fall-off threshold.
          const auto centre = d->sample_at(col, row, {0, 0});
          const double tol = shaders::kCellEdgeTolPx;
          const bool near_edge = std::min({std::abs(centre.screen_x + tol), std::abs(centre.screen_y + tol),
                                           std::abs(centre.screen_x - view.width() - tol),
                                           std::abs(centre.screen_y - view.height() - tol)}) < 1e-3;
          const bool kill_only = ((g.flags ^ r.flags) == shaders::kCellKilled);
          EXPECT_TRUE(near_edge || kill_only) << "cell " << col << "," << row << " gpu " << g.flags << " cpu " << r.flags;
          ++flag_mismatch;
          continue;
        }
        if (r.flags & (shaders::kCellPadding | shaders::kCellOffscreen)) continue;
        worst_px = std::max({worst_px, std::abs(double(g.screen_x) - r.screen_x), std::abs(double(g.screen_y) - r.screen_y)});
        worst_dir = std::max({worst_dir, std::abs(double(g.dir_x) - r.dir_x), std::abs(double(g.dir_y) - r.dir_y),
                              std::abs(double(g.dir_z) - r.dir_z)});
        EXPECT_NEAR(g.ecc_deg, r.ecc_deg, 2e-3) << col << "," << row;
        // Footprints of sub-pixel cells (log-polar centre) are limited by the float table.
        EXPECT_NEAR(g.footprint, r.footprint, 1e-3 * (1 + r.footprint)) << col << "," << row;
      }
    EXPECT_LE(flag_mismatch, d->columns() * d->rows() / 1000 + 2);
  }
  EXPECT_LT(worst_px, 0.01) << "worst display-position difference, pixels";
  EXPECT_LT(worst_dir, 1e-5);
  RecordProperty("worst_px", std::to_string(worst_px));
  std::printf("%s %s: worst |gpu - cpu| = %.2e px, %.2e in direction\n", c.display,
              core::distribution_name(c.kind), worst_px, worst_dir);
}

// With the lens' view mask (core::ViewMask, the layout the shader reads), the GPU grid hides
// exactly the cells the CPU reference hides with the same mask (ViewMask::visible_at); only
// cells within float rounding of a pixel edge may differ.
TEST_F(GpuTest, GridPassMaskMatchesCpuReference) {
  for (const char* name : {"tiny", "vive"}) {
    const core::DisplayPreset display = core::load_display(name);
    const core::EyeOptics optics(display, core::Eye::Right);
    const core::ViewMask mask = optics.view_mask();
    auto d = core::make_distribution(optics.view(), core::DistributionParams{});
    d->set_visibility(mask);
    gpu::GridPass pass(ctx());
    gpu::Buffer out(ctx(), {.size = gpu::GridPass::samples_bytes(*d), .memory = gpu::Memory::HostVisible});
    for (std::uint32_t f = 0; f < 2; ++f) {
      d->set_frame(glm::normalize(glm::dvec3(0.15 * f, -0.1 * f, -1.0)), f);
      pass.generate(*d, out, mask.words());
      const auto got = out.download<shaders::GridSample>();
      // The shader's own counts (FramePipeline::hidden_cells/traced_cells read them instead
      // of the grid) are exactly the grid's cells with those flags.
      std::int64_t gpu_traced = 0, gpu_hidden = 0;
      for (const auto& g : got) {
        gpu_traced += g.flags == 0 ? 1 : 0;
        gpu_hidden += g.flags == shaders::kCellHidden ? 1 : 0;
      }
      EXPECT_EQ(pass.counts().traced, gpu_traced) << name;
      EXPECT_EQ(pass.counts().hidden, gpu_hidden) << name;
      EXPECT_GT(gpu_hidden, 0) << name;
      int hidden = 0, mismatch = 0;
      for (int row = 0; row < d->padded_rows(); ++row)
        for (int col = 0; col < d->padded_columns(); ++col) {
          const auto& g = got[size_t(row) * d->padded_columns() + col];
          const auto r = d->sample(col, row);
          hidden += r.flags == shaders::kCellHidden ? 1 : 0;
          if (g.flags == r.flags || (r.flags & g.flags & shaders::kCellClipped)) continue;  // clipped: never traced
          const auto frac = [](double v) { return std::abs(v - std::round(v)); };
          EXPECT_LT(std::min(frac(r.screen_x), frac(r.screen_y)), 1e-3)
              << name << " cell " << col << "," << row << " gpu " << g.flags << " cpu " << r.flags;
          ++mismatch;
        }
      EXPECT_GT(hidden, 0) << name;
      EXPECT_LE(mismatch, hidden / 1000 + 2) << name;
    }
    // A mask smaller than the raster is refused before the GPU sees it.
    EXPECT_THROW(pass.prepare(*d, mask.words().first(mask.words().size() / 2)), std::invalid_argument);
  }
}

// The live-tile list (live_cells.h): exactly the tiles with a cell with a sample, in tile
// order, then those without one that hold a reset cell (one without a sample that had
// one in either of the two frames before; every such cell in the first two frames); the
// indirect dispatches cover each list with less than a row of idle workgroups. Under a
// moving gaze and the lens mask, for both ways of counting.
TEST_F(GpuTest, GridPassListsLiveAndResetTiles) {
  const core::DisplayPreset display = core::load_display("tiny");
  const core::EyeOptics optics(display, core::Eye::Left);
  const core::ViewMask mask = optics.view_mask();
  const std::uint32_t max_x = ctx().limits().maxComputeWorkGroupCount[0];
  for (const auto kind : {core::DistributionKind::VisualPolar, core::DistributionKind::Cartesian,
                          core::DistributionKind::LinearFalloff})
    for (const bool ballot : {true, false}) {
      const std::string what = std::string(core::distribution_name(kind)) + (ballot ? " ballot" : " atomic");
      core::DistributionParams p;
      p.kind = kind;
      auto d = core::make_distribution(optics.view(), p);
      d->set_visibility(mask);
      const std::uint32_t cells = std::uint32_t(d->padded_columns() * d->padded_rows());
      const std::uint32_t across = std::uint32_t(d->padded_columns()) / shaders::kPtTileColumns;
      const std::uint32_t tiles = cells / shaders::kLiveTileCells;
      gpu::GridPass pass(ctx(), 0, ballot);
      gpu::Buffer out(ctx(), {.size = gpu::GridPass::samples_bytes(*d), .memory = gpu::Memory::HostVisible});
      std::vector<std::uint32_t> history(cells, shaders::kLiveAllBefore);
      const glm::dvec3 gazes[] = {{0, 0, -1},      {0, 0, -1},       {0, 0, -1},
                                  {0.3, -0.2, -1}, {-0.4, 0.1, -1}, {-0.4, 0.1, -1}};
      for (std::uint32_t f = 0; f < std::size(gazes); ++f) {
        d->set_frame(glm::normalize(gazes[f]), 7);  // one frame index: the moves alone change the cells
        pass.generate(*d, out, mask.words());
        const auto grid = out.download<shaders::GridSample>();
        const auto list = pass.live_tiles().download<std::uint32_t>();
        const std::uint32_t* header = list.data();
        std::vector<int> live_in(tiles, 0), reset_in(tiles, 0);
        std::int64_t live_cells = 0, reset_cells = 0;
        for (std::uint32_t t = 0; t < tiles; ++t)
          for (std::uint32_t l = 0; l < shaders::kLiveTileCells; ++l) {
            const std::uint32_t i =
                shaders::live_tile_cell(shaders::live_tile_first(t, across), l, std::uint32_t(d->padded_columns()));
            const bool now = grid[i].flags == 0;
            const bool reset = !now && history[i] != 0;
            live_in[t] += now ? 1 : 0;
            reset_in[t] += reset ? 1 : 0;
            live_cells += now ? 1 : 0;
            reset_cells += reset ? 1 : 0;
            history[i] = ((history[i] << 1) | (now ? 1u : 0u)) & shaders::kLiveAllBefore;
          }
        EXPECT_EQ(f < 2, reset_cells + live_cells == cells) << what << " frame " << f;
        std::vector<std::uint32_t> live, reset;
        for (std::uint32_t t = 0; t < tiles; ++t)
          if (live_in[t] > 0) live.push_back(shaders::live_tile_first(t, across));
          else if (reset_in[t] > 0) reset.push_back(shaders::live_tile_first(t, across));
        ASSERT_EQ(header[shaders::kLiveCount], live.size()) << what << " frame " << f;
        ASSERT_EQ(header[shaders::kLiveResetCount], reset.size()) << what << " frame " << f;
        ASSERT_EQ(header[shaders::kLiveColumns], std::uint32_t(d->padded_columns()));
        EXPECT_EQ(pass.counts().traced, live_cells);
        EXPECT_EQ(pass.counts().reset, reset_cells);
        const std::uint32_t* entries = header + shaders::kLiveHeaderWords;
        // In tile order: the per-cell kernels sweep their buffers in order.
        const std::vector<std::uint32_t> got_live(entries, entries + live.size());
        const std::vector<std::uint32_t> got_reset(entries + live.size(), entries + live.size() + reset.size());
        EXPECT_EQ(got_live, live) << what << " frame " << f;
        EXPECT_EQ(got_reset, reset) << what << " frame " << f;
        const std::uint64_t changed = live.size() + reset.size();
        for (const auto& [at, groups] : {std::pair{shaders::kLiveArgsLive, std::uint64_t(live.size())},
                                         std::pair{shaders::kLiveArgsChanged, changed}}) {
          const std::uint64_t x = header[at], y = header[at + 1];
          EXPECT_EQ(header[at + 2], 1u);
          EXPECT_LE(x, max_x);
          EXPECT_GE(x * y, groups) << what;
          EXPECT_LT(x * y, groups + std::max<std::uint64_t>(y, 1)) << what << ": a row of groups or more idle";
        }
      }
      EXPECT_GT(pass.counts().hidden, 0) << what;
    }
}

const Case kCases[] = {
    {"tiny", core::DistributionKind::VisualPolar},       {"small", core::DistributionKind::VisualPolar},
#ifndef FOVEA_SANITIZED_BUILD
    {"fove0", core::DistributionKind::VisualPolar},
#endif
    {"small", core::DistributionKind::PaperVisualPolar},
    {"small", core::DistributionKind::Cartesian},        {"small", core::DistributionKind::CartesianUniform},
    {"small", core::DistributionKind::LinearFalloff},    {"small", core::DistributionKind::LogPolar},
};

INSTANTIATE_TEST_SUITE_P(Distributions, GridPassTest, ::testing::ValuesIn(kCases),
                         [](const auto& info) {
                           std::string n = std::string(info.param.display) + "_" + core::distribution_name(info.param.kind);
                           for (char& ch : n)
                             if (ch == '-') ch = '_';
                           return n;
                         });

}  // namespace
