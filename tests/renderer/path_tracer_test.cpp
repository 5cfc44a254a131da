// The grid path tracer on lavapipe: analytic furnace values, Cornell symmetry and
// convergence, robustness (fireflies, black albedo), reproducibility, skipped cells.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <numeric>
#include <random>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"
#include "fovea/core/error.hpp"
#include "fovea/renderer/procedural.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "fovea/shaders/pt_order.h"
#include "gpu_fixture.hpp"
#include "pt_helpers.hpp"

namespace fr = fovea::renderer;
namespace fc = fovea::core;
using fovea::test::mean_rgb;
using fovea::test::trace_grid;

namespace {

fc::View furnace_view(int size) { return fc::View(fc::Fov::from_degrees(-50, 50, 50, -50), size, size); }

bool all_finite(const std::vector<glm::vec4>& v) {
  for (const auto& p : v)
    for (int i = 0; i < 4; ++i)
      if (!std::isfinite(p[i])) return false;
  return true;
}

}  // namespace

class PathTracer : public fovea::test::GpuTest {};

// Unlimited bounces: L = Le / (1 − ρ) = 2 everywhere (ρ = 0.5, Le = 1). 4×4 cells keep
// the 65536 paths of unbounded length within a few seconds on lavapipe.
TEST_F(PathTracer, FurnaceConvergesToTwoAt4096Spp) {
  const fr::Scene s = fr::load_scene("furnace");
  fr::GpuScene g(ctx(), s);
  const fc::View v = furnace_view(4);
  fr::PathConfig c;
  c.spp = 256;
  c.max_bounces = -1;
  c.rr_start = 2;
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c, 16);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const glm::dvec3 m = mean_rgb(r.radiance);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(m[i], 2.0, 0.02) << "channel " << i;
  EXPECT_TRUE(all_finite(r.radiance));
  std::printf("furnace 4x4 @ 4096 spp: mean %.4f %.4f %.4f in %.2f s\n", m.x, m.y, m.z, secs);
}

// The default configuration (one bounce, NEE at both vertices) sums path lengths 0..2:
// Le(1 + ρ + ρ²) = 1.75; split (a) = Le + ρLe = 1.5 and (b) = ρ²Le = 0.25 before
// demodulation by ρ. Zero bounces: 1 + ρ = 1.5.
TEST_F(PathTracer, FurnaceBoundedBouncesMatchTheAnalyticSeries) {
  const fr::Scene s = fr::load_scene("furnace");
  fr::GpuScene g(ctx(), s);
  const fc::View v = furnace_view(8);
  fr::PathConfig c;
  c.spp = 64;
  const auto r = trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c, 4);
  EXPECT_NEAR(mean_rgb(r.radiance).x, 1.75, 0.0175);
  EXPECT_NEAR(mean_rgb(r.direct).x, 1.5 / 0.5, 0.03);
  EXPECT_NEAR(mean_rgb(r.indirect).x, 0.25 / 0.5, 0.005);
  EXPECT_NEAR(mean_rgb(r.albedo).x, 0.5, 1e-6);
  c.max_bounces = 0;
  const auto r0 = trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c, 2);
  EXPECT_NEAR(mean_rgb(r0.radiance).x, 1.5, 0.015);
  EXPECT_NEAR(mean_rgb(r0.indirect).x, 0.0, 1e-9);
  // Features of the primary hit: on the unit sphere around the eye, normals facing it.
  for (std::size_t i = 0; i < r.position_material.size(); ++i) {
    const glm::vec3 p(r.position_material[i]);
    EXPECT_NEAR(glm::length(p), 1.0f, 0.04f);  // flat facets inside the unit sphere
    EXPECT_LT(glm::dot(glm::vec3(r.normal_depth[i]), p), 0.0f);
    EXPECT_GT(r.normal_depth[i].w, 0.0f);
    EXPECT_EQ(r.position_material[i].w, 0.0f);
  }
}

TEST_F(PathTracer, FirefliesAndBlackAlbedoStayFinite) {
  fr::Scene s = fr::make_cornell();
  for (auto& m : s.materials) {
    if (m.emission.x > 0) m.emission = glm::vec3(1e6f);
    else m.base_color = m.name == "red" ? glm::vec3(0) : m.base_color;
  }
  s.materials[0].base_color = glm::vec3(0);
  s.materials[0].specular = 0.5f;
  s.materials[0].roughness = 0.02f;
  fr::sanitize(s, "fireflies");
  fr::GpuScene g(ctx(), s);
  const fc::View v(fc::Fov::from_degrees(-50, 50, 50, -50), 24, 24, s.camera);
  fr::PathConfig c;
  c.spp = 16;
  c.max_bounces = 4;
  c.rr_start = 1;
  const auto r = trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c);
  for (const auto* out : {&r.radiance, &r.direct, &r.indirect, &r.albedo, &r.normal_depth, &r.position_material})
    EXPECT_TRUE(all_finite(*out));
  EXPECT_GT(mean_rgb(r.radiance).x, 1.0);
}

TEST_F(PathTracer, RunsReproduceAndEyesAreDecorrelated) {
  const fr::Scene s = fr::load_scene("cornell");
  fr::GpuScene g(ctx(), s);
  const fc::View v(fc::Fov::from_degrees(-50, 50, 50, -50), 16, 16, s.camera);
  const auto grid = fr::cartesian_grid(v);
  const auto a = trace_grid(ctx(), g, grid, v, fc::Eye::Left, {});
  const auto b = trace_grid(ctx(), g, grid, v, fc::Eye::Left, {});
  const auto other_eye = trace_grid(ctx(), g, grid, v, fc::Eye::Right, {});
  const auto other_frame = trace_grid(ctx(), g, grid, v, fc::Eye::Left, {}, 1, 7);
  int same = 0, lit = 0, same_eye = 0, same_frame = 0;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    same += a.radiance[i] == b.radiance[i];
    if (a.indirect[i].x <= 0.0f) continue;  // rays leaving the open front carry no noise
    ++lit;
    same_eye += a.radiance[i] == other_eye.radiance[i];
    same_frame += a.radiance[i] == other_frame.radiance[i];
  }
  EXPECT_EQ(same, int(grid.size()));
  EXPECT_GT(lit, int(grid.size() / 4));
  EXPECT_EQ(same_eye, 0);
  EXPECT_EQ(same_frame, 0);
}

TEST_F(PathTracer, FlaggedCellsAreSkipped) {
  const fr::Scene s = fr::load_scene("cornell");
  fr::GpuScene g(ctx(), s);
  const fc::View v(fc::Fov::from_degrees(-50, 50, 50, -50), 8, 8, s.camera);
  auto grid = fr::cartesian_grid(v);
  for (std::size_t i = 0; i < grid.size(); i += 3) grid[i].flags = fovea::shaders::kCellClipped << (i % 5);
  const auto r = trace_grid(ctx(), g, grid, v, fc::Eye::Left, {});
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (grid[i].flags) {
      EXPECT_EQ(r.radiance[i], glm::vec4(0));
      EXPECT_EQ(r.position_material[i].w, -1.0f);
    } else {
      EXPECT_GE(r.position_material[i].w, 0.0f);  // the box is closed around the view
    }
  }
}

// GGX energy, light sampling: a furnace of rough white metal (F0 = 1) reflects its
// directional albedo E by NEE alone (zero bounces): L = 1 + E(wo), E = 1 with the
// multiple-scattering lobe (0.91 from single scattering alone). Bounds: 3 standard errors
// over the cells plus 0.003 for the albedo table's interpolation.
TEST_F(PathTracer, GgxFurnaceNeeConservesEnergy) {
  fr::Scene s = fr::make_furnace();
  s.materials[0].base_color = glm::vec3(1.0f);
  s.materials[0].metallic = 1.0f;
  s.materials[0].roughness = 0.5f;
  fr::sanitize(s, "ggx-furnace");
  fr::GpuScene g(ctx(), s);
  const fc::View v = furnace_view(8);
  fr::PathConfig c;
  c.spp = 64;
  c.max_bounces = 0;
  const auto r = trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c, 4);
  std::vector<double> cells;
  for (const auto& p : r.radiance) cells.push_back(p.x - 1.0);
  const fovea::test::MeanSe e = fovea::test::mean_se(cells);
  std::printf("GGX roughness 0.5, normal incidence: E = %.4f ± %.4f (NEE)\n", e.mean, e.se);
  EXPECT_LE(e.mean, 1.0 + 3.0 * e.se + 0.003);
  EXPECT_GE(e.mean, 0.97);
}

// GGX energy, BSDF sampling: a white metal floor under a constant white sky (no emitters)
// has radiance E(wo) = 1 (bounds as above); a Lambert floor exactly its albedo.
TEST_F(PathTracer, FloorUnderWhiteSkyReflectsItsAlbedo) {
  const fc::View v(fc::Fov::from_degrees(-30, 30, 30, -30), 8, 8,
                   fc::Pose{glm::angleAxis(-1.5707963, glm::dvec3(1, 0, 0)), {0, 0, 0}});  // looking down
  for (const float rough : {0.05f, 0.5f, -1.0f}) {
    fr::Scene s;
    s.environment = glm::vec3(1.0f);
    fr::Material m;
    if (rough > 0) {
      m.base_color = glm::vec3(1.0f);
      m.metallic = 1.0f;
      m.roughness = rough;
    } else {
      m.base_color = glm::vec3(0.5f);
      m.specular = 0.0f;
    }
    s.add_quad({-1000, -1, 1000}, {1000, -1, 1000}, {1000, -1, -1000}, {-1000, -1, -1000}, s.add_material(m));
    fr::sanitize(s, "floor");
    fr::GpuScene g(ctx(), s);
    fr::PathConfig c;
    c.spp = 64;
    const auto r = trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c, 2);
    std::vector<double> cells;
    for (const auto& p : r.radiance) cells.push_back(p.x);
    const fovea::test::MeanSe l = fovea::test::mean_se(cells);
    std::printf("floor %s: L = %.4f ± %.4f\n", rough > 0 ? ("GGX " + std::to_string(rough)).c_str() : "Lambert 0.5",
                l.mean, l.se);
    if (rough < 0) {
      EXPECT_NEAR(l.mean, 0.5, 1e-3);
    } else {
      EXPECT_LE(l.mean, 1.0 + 3.0 * l.se + 0.003);
      EXPECT_GE(l.mean, 0.97);
    }
  }
}

// The first hit's texture level of detail follows PathConfig::texture_cone: a wall of 8-texel
// blocks, each black or white at random, seen at 16 texels per cell, reads the blocks
// themselves (mip level 3, each cell black or white) with half a cell's cone (the frame
// pipeline's on a jittered grid), and level 4 (each texel the mean of 2×2 blocks) with a
// whole cell's; with no cone, the full-resolution texel.
TEST_F(PathTracer, TextureConeSelectsTheMipLevel) {
  constexpr int kTexels = 256, kBlock = 8, kCells = 16;
  fr::Scene s;
  s.environment = glm::vec3(1.0f);
  std::mt19937 rng(11);
  std::vector<std::uint8_t> block(std::size_t(kTexels / kBlock) * (kTexels / kBlock));
  for (auto& b : block) b = rng() % 2 ? 255 : 0;
  s.textures.push_back(fovea::test::grey_texture("blocks", kTexels, kTexels, [&](int x, int y) {
    return block[std::size_t(y / kBlock) * (kTexels / kBlock) + std::size_t(x / kBlock)];
  }));
  // A wall at z = −2 filling a ±20° view, its uv shifted a quarter of a level-3 texel so
  // that the cells' centres meet texel centres rather than the blocks' edges.
  const float h = 2.0f * float(std::tan(20.0 * std::numbers::pi / 180.0));
  s.add_quad({-h, -h, -2}, {h, -h, -2}, {h, h, -2}, {-h, h, -2}, s.add_material(fovea::test::textured_material(0)));
  for (std::size_t i = s.uvs.size() - 6; i < s.uvs.size(); ++i) s.uvs[i] += glm::vec2(1.0f / 64.0f);
  fr::sanitize(s, "blocks");
  fr::GpuScene g(ctx(), s);
  const fc::View v(fc::Fov::from_degrees(-20, 20, 20, -20), kCells, kCells);
  // The standard deviation of the first hits' albedo over the cells.
  auto contrast = [&](double cone) {
    fr::PathConfig c;
    c.max_bounces = 0;
    c.texture_cone = cone;
    const auto r = trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c);
    std::vector<double> a;
    for (const auto& p : r.albedo) a.push_back(p.x);
    const double mean = std::accumulate(a.begin(), a.end(), 0.0) / double(a.size());
    double var = 0;
    for (const double x : a) var += (x - mean) * (x - mean);
    return std::sqrt(var / double(a.size()));
  };
  const double full = contrast(0.0), half = contrast(0.5), whole = contrast(1.0);
  std::printf("albedo standard deviation over the cells: cone 0 %.3f, half a cell %.3f, a cell %.3f\n", full, half,
              whole);
  EXPECT_GT(full, 0.45);  // black or white: 0.5
  EXPECT_GT(half, 0.45);
  EXPECT_LT(whole, 0.35);  // the mean of four blocks: 0.25
}

// The tile order (pt_order.h) on grids of whole tiles: every cell exactly once, and every
// 8-lane SIMD vector (invocations 8k … 8k+7) 8 consecutive rows of one column.
TEST(TraceOrder, TilesCoverEveryCellOnceWithVectorsDownOneColumn) {
  using fovea::shaders::kPtTileColumns;
  using fovea::shaders::kPtTileRows;
  using fovea::shaders::pt_tile_cell;
  for (const auto& [columns, rows] : {std::pair<std::uint32_t, std::uint32_t>{8, 8}, {64, 32}, {640, 1504}}) {
    std::vector<int> hits(std::size_t(columns) * rows, 0);
    for (std::uint32_t n = 0; n < columns * rows; ++n) {
      const std::uint32_t c = pt_tile_cell(n, columns, columns * rows);
      ASSERT_LT(c, columns * rows) << columns << "x" << rows << ", invocation " << n;
      ++hits[c];
      if (n % 8 != 0) {
        ASSERT_EQ(c, pt_tile_cell(n - 1, columns, columns * rows) + columns)
            << columns << "x" << rows << ", invocation " << n;
      }
    }
    EXPECT_EQ(std::count(hits.begin(), hits.end(), 1), std::ptrdiff_t(hits.size())) << columns << "x" << rows;
  }
  EXPECT_EQ(kPtTileColumns * kPtTileRows, 64u);  // pt_trace.comp's workgroup: one tile each
}

// The workgroup -> tile map (shifts and masks, no division) is a permutation of the tiles for
// any count, takes s = the lowest set bit of the count (at most kPtTileStrips) strips, and
// gives the first half of the dispatch half of every strip of two tiles or more (± 1).
TEST(TraceOrder, WorkgroupsTakeEveryTileOnceFromEveryStrip) {
  using fovea::shaders::kPtTileStrips;
  using fovea::shaders::pt_tile_of_workgroup;
  for (const std::uint32_t tiles : {1u, 2u, 3u, 7u, 64u, 1800u, 4096u, 3072u, 20000u, 3u << 12, (1u << 20) + 4u}) {
    std::vector<int> hits(tiles, 0);
    for (std::uint32_t w = 0; w < tiles; ++w) {
      const std::uint32_t t = pt_tile_of_workgroup(w, tiles);
      ASSERT_LT(t, tiles) << tiles << " tiles, workgroup " << w;
      ++hits[t];
    }
    ASSERT_EQ(std::count(hits.begin(), hits.end(), 1), std::ptrdiff_t(tiles)) << tiles << " tiles";
    std::uint32_t s = 1;
    while (s < kPtTileStrips && tiles % (2 * s) == 0) s *= 2;
    const std::uint32_t per = tiles / s;  // tiles per strip
    if (per < 2) continue;
    std::vector<double> first_half(s, 0);
    for (std::uint32_t w = 0; w < tiles / 2; ++w) ++first_half[pt_tile_of_workgroup(w, tiles) / per];
    for (std::uint32_t k = 0; k < s; ++k) EXPECT_LE(std::abs(first_half[k] - per / 2.0), 1.0) << tiles << " tiles, strip " << k;
  }
}

// llvmpipe gives each of its k threads one contiguous 1/k of a dispatch's workgroups: each
// such part must hold about the same number of traced cells, though a Visual-Polar grid's
// padding (the rows above each inner column's last) sits in its high rows. Measured, least /
// most: 0.87-0.99 for 2-8 threads on small and fove0 (tiles row by row: 0.40-0.74).
TEST(TraceOrder, EveryContiguousPartOfTheWorkgroupsTracesAnEqualShare) {
  namespace core = fovea::core;
  using fovea::shaders::pt_tile_cell;
  for (const char* display : {"small", "fove0"}) {
    const core::View v = core::load_display(display).view(core::Eye::Left);
    auto d = core::make_distribution(v, core::DistributionParams{});
    d->set_frame(v.centre_dir());
    const auto columns = std::uint32_t(d->padded_columns()), rows = std::uint32_t(d->padded_rows());
    const std::uint32_t cells = columns * rows, workgroups = cells / 64;
    std::vector<bool> traced(cells);
    for (std::uint32_t i = 0; i < cells; ++i) traced[i] = d->sample(int(i % columns), int(i / columns)).flags == 0;
    for (const std::uint32_t threads : {2u, 3u, 4u, 8u}) {
      std::vector<double> share(threads, 0.0), row_major(threads, 0.0);
      const std::uint32_t per = workgroups / threads;  // lp_cs_tpool.c's split (the remainder: one each, last)
      for (std::uint32_t n = 0; n < per * threads * 64; ++n) {
        const std::uint32_t part = n / 64 / per;
        share[part] += traced[pt_tile_cell(n, columns, cells)];
        const std::uint32_t tile = n / 64, lane = n % 64, across = columns / 8;  // tiles row by row
        row_major[part] += traced[((tile / across) * 8 + lane % 8) * columns + (tile % across) * 8 + lane / 8];
      }
      const auto [lo, hi] = std::minmax_element(share.begin(), share.end());
      const auto [rlo, rhi] = std::minmax_element(row_major.begin(), row_major.end());
      std::printf("%s, %u tiles, %u threads: traced cells per part, least / most: %.3f (tiles row by row: %.3f)\n",
                  display, workgroups, threads, *lo / *hi, *rlo / *rhi);
      EXPECT_GT(*lo / *hi, 0.85) << display << ", " << threads << " threads";  // row by row: 0.40-0.74
    }
  }
}

namespace {
bool same_bits(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec4)) == 0;
}
}  // namespace

// The cell index, not the invocation, keys the random numbers and the outputs: tile and grid
// order give bit-identical buffers, with jitter, several samples per dispatch, accumulation
// over frames and skipped cells.
TEST_F(PathTracer, TileOrderTracesTheSameBuffersAsGridOrder) {
  const fr::Scene s = fr::load_scene("cornell");
  fr::GpuScene g(ctx(), s);
  const fc::View v(fc::Fov::from_degrees(-50, 50, 50, -50), 32, 24, s.camera);
  auto grid = fr::cartesian_grid(v);
  for (std::size_t i = 0; i < grid.size(); i += 7) grid[i].flags = fovea::shaders::kCellHidden;
  fr::PathConfig c;
  c.spp = 3;
  c.jitter = true;
  const fr::GridExtent extent{32, 24};
  const auto in_grid = trace_grid(ctx(), g, grid, v, fc::Eye::Right, c, 2, 5, extent);
  c.order = fr::TraceOrder::Tiles;
  const auto in_tiles = trace_grid(ctx(), g, grid, v, fc::Eye::Right, c, 2, 5, extent);
  EXPECT_TRUE(same_bits(in_grid.radiance, in_tiles.radiance));
  EXPECT_TRUE(same_bits(in_grid.direct, in_tiles.direct));
  EXPECT_TRUE(same_bits(in_grid.indirect, in_tiles.indirect));
  EXPECT_TRUE(same_bits(in_grid.albedo, in_tiles.albedo));
  EXPECT_TRUE(same_bits(in_grid.normal_depth, in_tiles.normal_depth));
  EXPECT_TRUE(same_bits(in_grid.position_material, in_tiles.position_material));
  // Not a vacuous comparison: the cells were traced (and differ from each other).
  EXPECT_GT(mean_rgb(in_tiles.radiance).x, 0.0);
  EXPECT_NE(in_tiles.radiance[1], in_tiles.radiance[2]);
}

// The tile order needs the grid's extent, in whole tiles.
TEST_F(PathTracer, TileOrderRefusesGridsWithoutWholeTiles) {
  const fr::Scene s = fr::load_scene("cornell");
  fr::GpuScene g(ctx(), s);
  const fc::View v(fc::Fov::from_degrees(-50, 50, 50, -50), 12, 8, s.camera);
  fr::PathConfig c;
  c.order = fr::TraceOrder::Tiles;
  EXPECT_THROW(trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c), fc::InputError);  // bound by size
  EXPECT_THROW(trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c, 1, 0, fr::GridExtent{12, 8}),
               fc::InputError);
  EXPECT_THROW(trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c, 1, 0, fr::GridExtent{0, 8}),
               fc::InputError);
}
