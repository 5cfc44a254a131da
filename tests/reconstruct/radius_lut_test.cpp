// The radius -> column lookup table (reconstruct::radius_lut) the reconstruction's mappings
// carry (recon_map.h, rg_column_range): for every radius the narrowed range holds the column
// the full search finds (the last whose r0 <= r, column 0 when none), on the column tables
// of real grids (both polar families, gaze centred, off centre, in a corner; the radii at
// every column boundary and one float step either side, between them, beyond the table,
// negative) and on degenerate tables; and it narrows the search to about one step.
#include "fovea/reconstruct/grid_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "fovea/core/display.hpp"

namespace core = fovea::core;
namespace reconstruct = fovea::reconstruct;
namespace shaders = fovea::shaders;

namespace {

// The full search of recon_map.h (rg_column_of over the whole table).
std::uint32_t full_search(const std::vector<shaders::GridColumn>& t, float r) {
  std::uint32_t c = 0;
  for (std::uint32_t i = 1; i < t.size(); ++i)
    if (t[i].r0 <= r) c = i;
  return c;
}

// rg_column_range's bin of r, in the shader's float arithmetic.
std::uint32_t bin_of(const reconstruct::RadiusLut& lut, float r) {
  const float last = float(shaders::kReconRadiusLutSize - 1u);
  const float x = std::clamp(r * lut.scale, 0.0f, last);
  return std::min(std::uint32_t(x), shaders::kReconRadiusLutSize - 1u);
}

// Checks every radius of `radii`; returns the mean width of the narrowed ranges (columns).
double check(const std::vector<shaders::GridColumn>& t, const std::vector<float>& radii, const char* what) {
  const reconstruct::RadiusLut lut = reconstruct::radius_lut(t);
  EXPECT_EQ(lut.entries.size(), shaders::kReconRadiusLutEntries) << what;
  EXPECT_GT(lut.scale, 0.0f) << what;
  EXPECT_TRUE(std::isfinite(lut.scale)) << what;
  if (lut.entries.size() != shaders::kReconRadiusLutEntries) return 0;
  for (std::uint32_t e : lut.entries) EXPECT_LT(e, t.size()) << what;
  double width = 0;
  for (float r : radii) {
    const std::uint32_t k = bin_of(lut, r), lo = lut.entries[k], hi = lut.entries[k + 2];
    const std::uint32_t want = full_search(t, r);
    EXPECT_LE(lo, want) << what << ", r = " << r << ", bin " << k;
    EXPECT_GE(hi, want) << what << ", r = " << r << ", bin " << k;
    width += hi - lo + 1;
  }
  return width / double(radii.size());
}

std::vector<float> radii_of(const std::vector<shaders::GridColumn>& t) {
  std::vector<float> r = {-1.0f, 0.0f, -0.0f, t.back().r1 * 1.5f, std::numeric_limits<float>::max()};
  for (const shaders::GridColumn& c : t)
    for (float x : {c.r0, c.r1, 0.5f * (c.r0 + c.r1)}) {
      r.push_back(x);
      r.push_back(std::nextafter(x, -1e30f));
      r.push_back(std::nextafter(x, 1e30f));
    }
  return r;
}

}  // namespace

TEST(RadiusLut, HoldsTheFullSearchColumnOnRealGrids) {
  for (const char* display : {"small", "fove0"})
    for (const auto kind : {core::DistributionKind::VisualPolar, core::DistributionKind::PaperVisualPolar}) {
      const core::View v = core::load_display(display).view(core::Eye::Left);
      core::DistributionParams p;
      p.kind = kind;
      auto d = core::make_distribution(v, p);
      for (const glm::dvec2 px : {glm::dvec2(0.5, 0.5), glm::dvec2(0.2, 0.35), glm::dvec2(0.02, 0.97)}) {
        d->set_frame(v.pixel_to_dir({px.x * v.width(), px.y * v.height()}));
        const auto& t = d->column_table();
        ASSERT_FALSE(t.empty());
        const std::string what = std::string(display) + ", " + core::distribution_name(kind) + ", gaze at (" +
                                 std::to_string(px.x) + ", " + std::to_string(px.y) + ")";
        const double width = check(t, radii_of(t), what.c_str());
        std::printf("%s: %zu columns, mean narrowed range %.2f columns\n", what.c_str(), t.size(), width);
        EXPECT_LT(width, 3.0) << what;  // ~1 search step instead of log2(columns)
      }
    }
}

TEST(RadiusLut, DegenerateTables) {
  using shaders::GridColumn;
  // One column; zero-width columns (equal r0); a table ending at radius 0; an empty one.
  check({GridColumn{0, 10, 8}}, {-1, 0, 5, 10, 11}, "one column");
  const std::vector<GridColumn> flat = {GridColumn{0, 1, 8}, GridColumn{1, 1, 8}, GridColumn{1, 1, 8},
                                        GridColumn{1, 2, 8}, GridColumn{2, 4, 8}};
  check(flat, radii_of(flat), "zero-width columns");
  const std::vector<GridColumn> zero = {GridColumn{0, 0, 1}, GridColumn{0, 0, 1}};
  check(zero, {0, 1e-7f, 1, 1e30f}, "a table of radius 0");
  const reconstruct::RadiusLut none = reconstruct::radius_lut({});
  EXPECT_TRUE(none.entries.empty());
  EXPECT_EQ(none.scale, 0.0f);
}
