// BMFR Phase I and the stereo gather (shaders/recon_accumulate.comp, recon_share.comp).
#include "bindings.hpp"
#include "buffers.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/reconstruct/stages.hpp"
#include "fovea/shaders/recon_grid.h"

namespace fovea::reconstruct {

Accumulation::Accumulation(gpu::Context& ctx, std::span<const EyeGrid> eyes, const gpu::Buffer& materials)
    : kernel_(kernel<AccumulateBindings, shaders::ReconAccumulatePush>(ctx, "recon_accumulate.comp.spv")),
      eyes_(eyes.size()) {
  for (std::size_t i = 0; i < eyes.size(); ++i) {
    const EyeGrid& g = eyes[i];
    Eye& e = eyes_[i];
    e.cells = g.cells;
    e.live = &live_list(g.live);
    for (int p = 0; p < 2; ++p) {
      e.direct[p] = cells(ctx, g.cells, "recon.acc_direct");
      e.indirect[p] = cells(ctx, g.cells, "recon.acc_indirect");
      e.pos[p] = cells(ctx, g.cells, "recon.vpos");
      e.nrm[p] = cells(ctx, g.cells, "recon.vnrm");
      e.restart[p] = cells(ctx, g.cells, "recon.restart", VK_FORMAT_R32_SFLOAT);
      e.albedo[p] = cells(ctx, g.cells, "recon.acc_albedo");
    }
    e.tap_idx = cells(ctx, g.cells, "recon.tap_idx", VK_FORMAT_R32G32B32A32_UINT);
    e.tap_w = cells(ctx, g.cells, "recon.tap_w");
    for (int p = 0; p < 2; ++p) {
      const int q = 1 - p;  // history read by a frame writing p
      e.set[p] = make_set(ctx, kernel_,
                          AccumulateBindings{g.maps(), g.tables(), g.samples, g.direct, g.indirect, g.normal_depth,
                                             g.position_material, &e.direct[q], &e.indirect[q], &e.pos[q], &e.nrm[q],
                                             &e.direct[p], &e.indirect[p], &e.pos[p], &e.nrm[p], &e.tap_idx, &e.tap_w,
                                             &materials, &e.restart[q], &e.restart[p], g.luts(), g.albedo, &e.albedo[q],
                                             &e.albedo[p], e.live});
    }
  }
}

void Accumulation::record(VkCommandBuffer cmd, int parity, bool history, std::span<const bool> fresh,
                          std::span<const bool> unmoved, const ReconSettings& s) const {
  for (std::size_t i = 0; i < eyes_.size(); ++i) {
    const Eye& e = eyes_[i];
    run_cells(cmd, kernel_, e.set[parity],
              shaders::ReconAccumulatePush{e.cells, history ? 1u : 0u, fresh[i] ? 1u : 0u, s.live_cells ? 1u : 0u,
                                           s.alpha_min, s.coarse_keep, s.coarse_reject, s.landing_deg,
                                           s.landing_history, s.motion_deg / kHeldCellShare,
                                           unmoved[i] ? 1u : 0u, 0},
              e.cells, e.live);
  }
  gpu::compute_to_compute(cmd);
}

void Accumulation::fill(VkCommandBuffer cmd, std::uint32_t word) const {
  for (const Eye& e : eyes_) {
    for (int p = 0; p < 2; ++p)
      for (const gpu::Buffer* b : {&e.direct[p], &e.indirect[p], &e.pos[p], &e.nrm[p], &e.restart[p], &e.albedo[p]})
        gpu::fill_buffer(cmd, *b, word);
    gpu::fill_buffer(cmd, e.tap_idx, word);
    gpu::fill_buffer(cmd, e.tap_w, word);
  }
}

StereoGather::StereoGather(gpu::Context& ctx, std::span<const EyeGrid> eyes, const Accumulation& acc)
    : kernel_(kernel<ShareBindings, shaders::ReconSharePush>(ctx, "recon_share.comp.spv")), eyes_(eyes.size()) {
  for (std::size_t i = 0; i < eyes.size(); ++i) {
    const EyeGrid& g = eyes[i];
    Eye& e = eyes_[i];
    e.cells = g.cells;
    e.live = &live_list(g.live);
    e.shared = cells(ctx, g.cells, "recon.shared_indirect");
    e.z = cells(ctx, g.cells, "recon.z");
    e.edge = cells(ctx, g.cells, "recon.edge", VK_FORMAT_R32_UINT);
    const int me = int(i), other = eyes.size() == 2 ? 1 - me : me;  // one eye gathers from itself (unused)
    for (int p = 0; p < 2; ++p)
      e.set[p] = make_set(ctx, kernel_,
                          ShareBindings{g.maps(), g.tables(), &acc.position(me, p), &acc.normal(me, p),
                                        &acc.direct(me, p), &acc.indirect(me, p), &acc.position(other, p),
                                        &acc.normal(other, p), &acc.indirect(other, p), &e.shared, &e.z, &e.edge,
                                        g.luts(), e.live});
  }
}

void StereoGather::record(VkCommandBuffer cmd, int parity, bool share, const ReconSettings& s) const {
  for (const Eye& e : eyes_)
    run_cells(cmd, kernel_, e.set[parity],
              shaders::ReconSharePush{e.cells, share ? 1u : 0u, s.coarse_keep, s.coarse_reject,
                                      s.denoiser == Denoiser::Bmfr ? 1u : 0u, s.live_cells ? 1u : 0u, 0, 0},
              e.cells, e.live);
  gpu::compute_to_compute(cmd);
}

void StereoGather::fill(VkCommandBuffer cmd, std::uint32_t word) const {
  for (const Eye& e : eyes_) {
    gpu::fill_buffer(cmd, e.shared, word);
    gpu::fill_buffer(cmd, e.z, word);
    gpu::fill_buffer(cmd, e.edge, word);
  }
}

}  // namespace fovea::reconstruct
