// BMFR Phase III, TAA and albedo re-modulation (shaders/recon_post.comp, recon_taa.comp).
#include "bindings.hpp"
#include "buffers.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/reconstruct/stages.hpp"
#include "fovea/shaders/recon_grid.h"

namespace fovea::reconstruct {

PostTaa::PostTaa(gpu::Context& ctx, std::span<const EyeGrid> eyes, const Accumulation& acc,
                 const StereoGather& gather, const Bmfr* bmfr, bool final_albedo)
    : post_(kernel<PostBindings, shaders::ReconPostPush>(ctx, "recon_post.comp.spv")),
      taa_(kernel<TaaBindings, shaders::ReconPostPush>(ctx, "recon_taa.comp.spv",
                                                       {gpu::SpecConstant::boolean(0, final_albedo)})),
      eyes_(eyes.size()) {
  for (std::size_t i = 0; i < eyes.size(); ++i) {
    const EyeGrid& g = eyes[i];
    Eye& e = eyes_[i];
    const int me = int(i);
    e.cells = g.cells;
    e.live = &live_list(g.live);
    for (int p = 0; p < 2; ++p) {
      e.post[p] = cells(ctx, g.cells, "recon.post");
      e.final_[p] = cells(ctx, g.cells, "recon.final");
      e.final_albedo[p] = cells(ctx, final_albedo ? g.cells : 1, "recon.final_albedo");
    }
    e.sum = cells(ctx, g.cells, "recon.post_sum");
    const gpu::Buffer* source = bmfr ? &bmfr->fitted(me) : &gather.z(me);
    const gpu::Buffer* excess = bmfr ? &bmfr->excess(me) : source;  // unread without BMFR
    for (int p = 0; p < 2; ++p) {
      const int q = 1 - p;
      e.post_set[p] = make_set(ctx, post_,
                               PostBindings{&acc.position(me, p), &acc.tap_index(me), &acc.tap_weight(me), source,
                                            &acc.direct(me, p), &e.post[q], &e.post[p], &acc.direct(me, q), excess,
                                            &e.sum, e.live, g.direct});
      e.taa_set[p] = make_set(ctx, taa_,
                              TaaBindings{g.maps(), g.tables(), &acc.position(me, p), &acc.tap_index(me),
                                          &acc.tap_weight(me), &e.sum, &acc.albedo(me, p), &e.final_[q], &e.final_[p],
                                          &acc.normal(me, p), &acc.restart(me, p), e.live, &e.final_albedo[q],
                                          &e.final_albedo[p]});
    }
  }
}

namespace {
shaders::ReconPostPush post_push(bool history, const ReconSettings& s) {
  return {0, history ? 1u : 0u, s.denoiser == Denoiser::Bmfr ? 1u : 0u, s.live_cells ? 1u : 0u, s.post_alpha_min,
          s.taa_alpha, s.still, s.landing_deg};
}
}  // namespace

void PostTaa::record(VkCommandBuffer cmd, int parity, bool history, const ReconSettings& s) const {
  record_post(cmd, parity, history, s);
  record_taa(cmd, parity, history, s);
}

void PostTaa::record_post(VkCommandBuffer cmd, int parity, bool history, const ReconSettings& s) const {
  shaders::ReconPostPush push = post_push(history, s);
  for (const Eye& e : eyes_) {
    push.cells = e.cells;
    run_cells(cmd, post_, e.post_set[parity], push, e.cells, e.live);
  }
  gpu::compute_to_compute(cmd);
}

void PostTaa::record_taa(VkCommandBuffer cmd, int parity, bool history, const ReconSettings& s) const {
  shaders::ReconPostPush push = post_push(history, s);
  for (const Eye& e : eyes_) {
    push.cells = e.cells;
    run_cells(cmd, taa_, e.taa_set[parity], push, e.cells, e.live);
  }
  gpu::compute_to_transfer(cmd);
}

void PostTaa::fill(VkCommandBuffer cmd, std::uint32_t word) const {
  for (const Eye& e : eyes_) {
    for (int p = 0; p < 2; ++p) {
      gpu::fill_buffer(cmd, e.post[p], word);
      gpu::fill_buffer(cmd, e.final_[p], word);
      gpu::fill_buffer(cmd, e.final_albedo[p], word);
    }
    gpu::fill_buffer(cmd, e.sum, word);
  }
}

}  // namespace fovea::reconstruct
