// Resolve to the display (shaders/recon_mip.comp, recon_radius_lut.comp, recon_resolve.comp
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
}  // namespace

Resolve::Resolve(gpu::Context& ctx, std::span<const EyeGrid> eyes, const Accumulation& acc)
    : mip_(kernel<MipBindings, shaders::ReconMipPush>(ctx, "recon_mip.comp.spv")),
      resolve_(kernel<ResolveBindings, shaders::ReconResolvePush>(ctx, "recon_resolve.comp.spv")),
      blur_(kernel<BlurBindings, shaders::ReconBlurPush>(ctx, "recon_blur.comp.spv")),
      lut_(kernel<RadiusLutBindings, shaders::ReconResolvePush>(ctx, "recon_radius_lut.comp.spv")),
      eyes_(eyes.size()) {
  for (std::size_t i = 0; i < eyes.size(); ++i) {
    const EyeGrid& g = eyes[i];
    Eye& e = eyes_[i];
    e.cells = g.cells;
    e.width = g.width;
    e.height = g.height;
    e.padded_columns = g.padded_columns;
    e.polar = g.polar;
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
    e.mips = storage(ctx, VkDeviceSize(offset) * 16, "recon.mips");
    e.offsets = storage(ctx, e.level_offset.size() * 4, "recon.mip_offsets");
    e.offsets.upload(e.level_offset);
    const VkDeviceSize screen = VkDeviceSize(g.width) * g.height * 16;
    e.screen_a = storage(ctx, screen, "recon.screen");
    e.screen_b = storage(ctx, screen, "recon.screen_tmp");
    e.depth = storage(ctx, screen / 4, "recon.depth");
    e.lut = storage(ctx, sizeof(shaders::ReconRadiusLutHeader) + (shaders::kReconRadiusLutSize + 2) * 4, "recon.radius_lut");
    e.mip_set = make_set(ctx, mip_, MipBindings{g.maps, g.tables, &e.mips});
    e.lut_set = make_set(ctx, lut_, RadiusLutBindings{g.maps, g.tables, &e.lut});
    for (int p = 0; p < 2; ++p)
      e.resolve_set[p] = make_set(ctx, resolve_, ResolveBindings{g.maps, g.tables, &e.mips, &e.offsets, &e.screen_a,
                                                                 &acc.position(int(i), p), &e.depth, &e.lut});
    e.blur_h = make_set(ctx, blur_, BlurBindings{g.maps, g.tables, &e.screen_a, &e.screen_b});
    e.blur_v = make_set(ctx, blur_, BlurBindings{g.maps, g.tables, &e.screen_b, &e.screen_a});
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
  record_mips(cmd);
  record_resample(cmd, parity);
  if (blur) record_blur(cmd, s);
}

void Resolve::record_mips(VkCommandBuffer cmd) const {
  for (std::uint32_t l = 0; l + 1 < max_levels(); ++l) {
    for (const Eye& e : eyes_) {
      if (l + 1 >= e.levels) continue;
      const shaders::ReconMipPush push{e.padded_columns, e.level_rows[l], e.level_rows[l + 1], l, e.level_offset[l],
                                       e.level_offset[l + 1], 0, 0};
      mip_.run(cmd, {&e.mip_set}, push, e.padded_columns, e.level_rows[l + 1]);
    }
    gpu::compute_to_compute(cmd);
  }
}

void Resolve::record_resample(VkCommandBuffer cmd, int parity, bool grid_coords) const {
  for (const Eye& e : eyes_)
    if (e.polar) lut_.run(cmd, {&e.lut_set}, shaders::ReconResolvePush{}, shaders::kReconRadiusLutSize + 2);
  gpu::compute_to_compute(cmd);
  for (const Eye& e : eyes_)
    resolve_.run(cmd, {&e.resolve_set[parity]}, shaders::ReconResolvePush{e.width, e.height, e.levels, grid_coords ? 1u : 0u}, e.width,
                 e.height);
  gpu::compute_to_compute(cmd);
}

void Resolve::record_blur(VkCommandBuffer cmd, const ReconSettings& s) const {
  for (int pass = 0; pass < 2; ++pass) {
    for (const Eye& e : eyes_) {
      const shaders::ReconBlurPush push{e.width, e.height, std::uint32_t(pass), 0,
                                        float(blur_sigma_deg(0.0, s.blur_mar_fovea_deg)), float(s.blur_min_sigma_px),
                                        float(s.blur_max_sigma_px), blur_skip_cos(s, e.max_pixels_per_deg)};
      blur_.run(cmd, {pass == 0 ? &e.blur_h : &e.blur_v}, push, e.width, e.height);
    }
    gpu::compute_to_compute(cmd);
  }
}

void Resolve::fill(VkCommandBuffer cmd, std::uint32_t word) const {
  for (const Eye& e : eyes_)
    for (const gpu::Buffer* b : {&e.mips, &e.screen_a, &e.screen_b, &e.depth, &e.lut}) gpu::fill_buffer(cmd, *b, word);
}

}  // namespace fovea::reconstruct
