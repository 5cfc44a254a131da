// Resolve to the display (shaders/recon_grid_blur.comp, recon_mip.comp, recon_resolve.comp
// with the display-space depth, recon_blur.comp).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "bindings.hpp"
#include "buffers.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/reconstruct/stages.hpp"
#include "fovea/shaders/recon_grid.h"

namespace fovea::reconstruct {

namespace {
constexpr std::uint32_t kMaxMipLevels = 12;

// cos of the eccentricity within which no pixel of a raster of at most `ppd` pixels/degree
// gets a kernel of min_sigma_px or more (σ grows with e): the blur copies those pixels
// after one dot product.
float blur_skip_cos(const ReconSettings& s, double ppd) {
  double lo = 0, hi = 180;
  if (blur_sigma_deg(0, s.blur_mar_fovea_deg) * ppd >= s.blur_min_sigma_px) return 2.0f;  // nothing skipped
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (blur_sigma_deg(mid, s.blur_mar_fovea_deg) * ppd < s.blur_min_sigma_px ? lo : hi) = mid;
  }
  return float(std::cos(lo * std::numbers::pi / 180));
}

bool grid_space_blur(const shaders::ReconGrid& m) { return m.g.family == shaders::kFamilyAngularPolar; }

// The first column of an angular polar mapping whose acuity kernel (recon_grid_blur.comp) is
// at least min_sigma_px cells wide across or along it, or `columns` when none is: the blur
// passes start there (σ in cells grows outwards; columns beyond it below the limit are copied).
std::uint32_t first_blurred_column(const GridMapping& mapping, const ReconSettings& s) {
  const shaders::ReconGrid& m = mapping.current();
  const std::span<const shaders::GridColumn> table = mapping.current_table();
  for (std::uint32_t c = 0; c < m.g.columns && c < table.size(); ++c) {
    const shaders::GridColumn& col = table[c];
    const double e = 0.5 * (double(col.r0) + double(col.r1));
    const double arc = 1.0 - double(col.phi_gap) / (2 * std::numbers::pi);
    const double row_deg = 360.0 * std::sin(e * std::numbers::pi / 180) * arc / std::max(col.rows, 1u);
    const double sigma = blur_sigma_deg(e, s.blur_mar_fovea_deg);
    if (sigma >= s.blur_min_sigma_px * std::min(double(col.r1 - col.r0), row_deg)) return c;
  }
  return m.g.columns;
}

// Which part of the φ-mip chain the resample can reach this frame. A pixel in column c (its
// radius in [r0, r1]) has a footprint along φ of at most
//   F_c = δ·turn_rows / (2π·min(sin r0, sin r1))   (angular; δ the raster's largest pixel
//   angle, bounded by the tangent-space step)   or   turn_rows / (2π·r0)   (screen polar)
// rows (recon_resolve.comp, phi_footprint), so its LOD log2(F) needs level L only where
// F_c > 2^(L−1). Level L is built for the columns up to the last such one plus its
// neighbour (the bilinear pair); the resample computes the LOD only below lod_columns.
struct MipReach {
  std::vector<std::uint32_t> columns;  // per level ≥ 1: columns [0, n) to build (0: none)
  std::uint32_t lod_columns = 0;       // columns whose pixels can have a LOD > 0
};

MipReach mip_reach(const GridMapping& mapping, std::uint32_t levels) {
  const shaders::ReconGrid& m = mapping.current();
  MipReach reach;
  reach.columns.assign(levels, 0);
  if (m.g.family == shaders::kFamilyCartesian) return reach;
  const std::span<const shaders::GridColumn> table = mapping.current_table();
  const double delta = std::max((m.g.tan_right - m.g.tan_left) / m.g.width, (m.g.tan_up - m.g.tan_down) / m.g.height);
  constexpr double kDeg = std::numbers::pi / 180;
  for (std::uint32_t c = 0; c < m.g.columns && c < table.size(); ++c) {
    const shaders::GridColumn& col = table[c];
    const double turn_rows = col.rows / (1.0 - double(col.phi_gap) / (2 * std::numbers::pi));
    const double f = m.g.family == shaders::kFamilyAngularPolar
                         ? delta * turn_rows / (2 * std::numbers::pi * std::min(std::sin(col.r0 * kDeg), std::sin(col.r1 * kDeg)))
                         : turn_rows / (2 * std::numbers::pi * col.r0);
    if (!(f > 1.0)) continue;  // also a NaN-free guard: r0 = 0 gives +inf, which counts
    reach.lod_columns = c + 1;
    for (std::uint32_t l = 1; l < levels && f > std::ldexp(1.0, int(l) - 1); ++l)
      reach.columns[l] = std::min(c + 2, m.g.padded_columns);
  }
  return reach;
}
// recon_temporal.comp's invocations (runs of kReconTemporalRun pixels per row), one running sum each.
std::uint32_t temporal_runs(std::uint32_t width, std::uint32_t height) {
  return (width + shaders::kReconTemporalRun - 1) / shaders::kReconTemporalRun * height;
}
}  // namespace

Resolve::Resolve(gpu::Context& ctx, std::span<const EyeGrid> eyes, const Accumulation& acc, const PostTaa& post)
    : mip_(kernel<MipBindings, shaders::ReconMipPush>(ctx, "recon_mip.comp.spv")),
      resolve_(kernel<ResolveBindings, shaders::ReconResolvePush>(ctx, "recon_resolve.comp.spv")),
      blur_(kernel<BlurBindings, shaders::ReconBlurPush>(ctx, "recon_blur.comp.spv")),
      grid_blur_(kernel<BlurBindings, shaders::ReconGridBlurPush>(ctx, "recon_grid_blur.comp.spv")),
      temporal_(kernel<TemporalBindings, shaders::ReconTemporalPush>(ctx, "recon_temporal.comp.spv")),
      eyes_(eyes.size()) {
  for (std::size_t i = 0; i < eyes.size(); ++i) {
    const EyeGrid& g = eyes[i];
    Eye& e = eyes_[i];
    e.cells = g.cells;
    e.width = g.width;
    e.height = g.height;
    e.padded_columns = g.padded_columns;
    e.polar = g.polar;
    e.mapping = g.mapping;
    e.max_pixels_per_deg = g.max_pixels_per_deg;
    // φ-only mip chain (polar grids): level l has ceil(rows / 2^l) rows.
    std::uint32_t rows = g.padded_rows, offset = 0;
    do {
      e.level_rows.push_back(rows);
      e.level_offset.push_back(offset);
      offset += rows * g.padded_columns;
      rows = (rows + 1) / 2;
    } while (g.polar && e.level_rows.back() > 1 && e.level_rows.size() < kMaxMipLevels);
    e.levels = std::uint32_t(e.level_rows.size());
    e.mips = cells(ctx, offset, "recon.mips");
    e.offsets = storage(ctx, e.level_offset.size() * 4, "recon.mip_offsets");
    e.offsets.upload(e.level_offset);
    const std::uint32_t pixels = g.width * g.height;
    e.screen_a = cells(ctx, pixels, "recon.screen");
    e.screen_b = cells(ctx, pixels, "recon.screen_tmp");
    e.depth = storage(ctx, VkDeviceSize(pixels) * 4, "recon.depth");
    e.mip_set = make_set(ctx, mip_, MipBindings{g.maps(), g.tables(), &e.mips});
    e.has_primary = g.primary != nullptr;
    if (e.has_primary && post.final_albedo(int(i), 0).size() < VkDeviceSize(g.cells) * 16)
      throw core::InputError("resolve: the display pixels' first hits need TAA's output albedo (PostTaa final_albedo)");
    if (!e.has_primary) e.no_primary = cells(ctx, 1, "recon.no_primary");  // bound, never read
    for (int p = 0; p < 2; ++p)
      e.resolve_set[p] = make_set(ctx, resolve_,
                                  ResolveBindings{g.maps(), g.tables(), &e.mips, &e.offsets, &e.screen_a,
                                                  &acc.position(int(i), p), &e.depth, g.luts(),
                                                  &post.final_albedo(int(i), p),
                                                  e.has_primary ? g.primary : &e.no_primary});
    e.prev_luma = storage(ctx, VkDeviceSize(pixels) * 4, "recon.temporal_prev_luma");
    e.temporal_sums = storage(ctx, VkDeviceSize(temporal_runs(g.width, g.height)) * 4, "recon.temporal_sums");
    e.temporal_sums.upload(std::vector<float>(temporal_runs(g.width, g.height), 0.0f));
    e.temporal_set = make_set(ctx, temporal_, TemporalBindings{&e.screen_a, &e.prev_luma, &e.temporal_sums});
    e.blur_h = make_set(ctx, blur_, BlurBindings{g.maps(), g.tables(), &e.screen_a, &e.screen_b});
    e.blur_v = make_set(ctx, blur_, BlurBindings{g.maps(), g.tables(), &e.screen_b, &e.screen_a});
    if (g.polar) {  // grid-space blur: level 0 -> grid_tmp (across columns) -> level 0 (along φ)
      e.grid_tmp = cells(ctx, g.padded_rows * g.padded_columns, "recon.grid_blur_tmp");
      e.grid_blur_rho = make_set(ctx, grid_blur_, BlurBindings{g.maps(), g.tables(), &e.mips, &e.grid_tmp});
      e.grid_blur_phi = make_set(ctx, grid_blur_, BlurBindings{g.maps(), g.tables(), &e.grid_tmp, &e.mips});
    }
  }
}

std::uint32_t Resolve::max_levels() const {
  std::uint32_t m = 1;
  for (const Eye& e : eyes_) m = std::max(m, e.levels);
  return m;
}

void Resolve::record_copy(VkCommandBuffer cmd, std::span<const gpu::Buffer* const> grid_images) const {
  for (std::size_t i = 0; i < eyes_.size(); ++i)
    gpu::copy_buffer(cmd, *grid_images[i], eyes_[i].mips, VkDeviceSize(eyes_[i].cells) * 16);
  gpu::transfer_to_compute(cmd);
}

void Resolve::record_resolve(VkCommandBuffer cmd, int parity, bool blur, const ReconSettings& s) const {
  if (blur) record_grid_blur(cmd, s);
  record_mips(cmd);
  record_resample(cmd, parity, s);
  if (blur) record_blur(cmd, s);
}

void Resolve::record_grid_blur(VkCommandBuffer cmd, const ReconSettings& s) const {
  std::vector<std::uint32_t> first(eyes_.size(), 0);
  bool any = false;
  for (std::size_t i = 0; i < eyes_.size(); ++i) {
    const shaders::ReconGrid& m = eyes_[i].mapping->current();
    first[i] = grid_space_blur(m) ? first_blurred_column(*eyes_[i].mapping, s) : m.g.columns;
    any = any || first[i] < m.g.columns;
  }
  if (!any) return;  // the acuity kernel is below min σ in every cell: nothing to blur
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < eyes_.size(); ++i) {
      const Eye& e = eyes_[i];
      const std::uint32_t columns = e.mapping->current().g.columns;
      if (first[i] >= columns) continue;
      const shaders::ReconGridBlurPush push{first[i], std::uint32_t(pass), 0, 0,
                                            float(blur_sigma_deg(0.0, s.blur_mar_fovea_deg)),
                                            float(s.blur_min_sigma_px), float(s.blur_max_sigma_px), 0};
      grid_blur_.run(cmd, {pass == 0 ? &e.grid_blur_rho : &e.grid_blur_phi}, push, columns - first[i], e.level_rows[0]);
    }
    gpu::compute_to_compute(cmd);
  }
}

void Resolve::record_mips(VkCommandBuffer cmd) const {
  std::vector<MipReach> reach;
  for (const Eye& e : eyes_) reach.push_back(mip_reach(*e.mapping, e.levels));
  for (std::uint32_t l = 0; l + 1 < max_levels(); ++l) {
    bool any = false;
    for (std::size_t i = 0; i < eyes_.size(); ++i) {
      const Eye& e = eyes_[i];
      const std::uint32_t columns = l + 1 < e.levels ? reach[i].columns[l + 1] : 0;
      if (columns == 0) continue;
      const shaders::ReconMipPush push{e.padded_columns, e.level_rows[l], e.level_rows[l + 1], l, e.level_offset[l],
                                       e.level_offset[l + 1], 0, 0};
      mip_.run(cmd, {&e.mip_set}, push, columns, e.level_rows[l + 1]);
      any = true;
    }
    if (!any) break;
    gpu::compute_to_compute(cmd);
  }
}

void Resolve::set_detail(int eye, const DetailWindow& window) {
  Eye& e = eyes_.at(std::size_t(eye));
  if (window.width > 0 && window.height > 0 &&
      (window.x0 + window.width > e.width || window.y0 + window.height > e.height || !e.has_primary))
    throw core::InputError("resolve: detail window outside the display or an eye without first hits");
  e.detail = window;
}

void Resolve::record_resample(VkCommandBuffer cmd, int parity, const ReconSettings& s, bool grid_coords) const {
  for (const Eye& e : eyes_) {
    const std::uint32_t lod_columns = mip_reach(*e.mapping, e.levels).lod_columns;
    const DetailWindow& d = e.detail;
    const bool detail = !grid_coords && d.width > 0 && d.height > 0;
    resolve_.run(cmd, {&e.resolve_set[parity]},
                 shaders::ReconResolvePush{e.width, e.height, e.levels, grid_coords ? 1u : 0u, lod_columns,
                                           depth_output_ ? 1u : 0u, 0, 0, d.x0, d.y0, detail ? d.width : 0u,
                                           d.height, d.cos_full, d.cos_none,
                                           s.lattice_blur && !grid_coords ? 1u : 0u,
                                           s.raster_gaussian ? float(raster_filter_side_weight()) : 0.0f},
                 e.width, e.height);
  }
  gpu::compute_to_compute(cmd);
}

void Resolve::record_blur(VkCommandBuffer cmd, const ReconSettings& s) const {
  for (int pass = 0; pass < 2; ++pass) {
    for (const Eye& e : eyes_) {
      if (grid_space_blur(e.mapping->current())) continue;  // blurred in grid space (record_grid_blur)
      const shaders::ReconBlurPush push{e.width, e.height, std::uint32_t(pass), 0,
                                        float(blur_sigma_deg(0.0, s.blur_mar_fovea_deg)), float(s.blur_min_sigma_px),
                                        float(s.blur_max_sigma_px), blur_skip_cos(s, e.max_pixels_per_deg)};
      blur_.run(cmd, {pass == 0 ? &e.blur_h : &e.blur_v}, push, e.width, e.height);
    }
    gpu::compute_to_compute(cmd);
  }
}

void Resolve::record_temporal(VkCommandBuffer cmd, bool accumulate) const {
  for (const Eye& e : eyes_)
    temporal_.run(cmd, {&e.temporal_set}, shaders::ReconTemporalPush{e.width, e.height, accumulate ? 1u : 0u, 0},
                  temporal_runs(e.width, e.height));
  gpu::compute_to_compute(cmd);
}

double Resolve::temporal_abs_luma_sum(int eye) const {
  double sum = 0;
  for (float s : eyes_.at(std::size_t(eye)).temporal_sums.download<float>()) sum += s;
  return sum;
}

void Resolve::fill(VkCommandBuffer cmd, std::uint32_t word) const {
  for (const Eye& e : eyes_)
    for (const gpu::Buffer* b : {&e.mips, &e.screen_a, &e.screen_b, &e.depth, &e.grid_tmp, &e.no_primary})
      if (b->size() > 0) gpu::fill_buffer(cmd, *b, word);
}

}  // namespace fovea::reconstruct
