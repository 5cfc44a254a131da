#include "fovea/compositor/bmfr.hpp"

#include <string>

#include "fovea/core/error.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/shaders/recon_grid.h"

namespace fovea::compositor {

namespace {

std::uint32_t checked_workgroup(const BmfrOptions& o) {
  const std::uint32_t w = o.workgroup ? o.workgroup : kBmfrDefaultWorkgroup;
  if (w < 8 || w > 512 || 1024 % w != 0)
    throw core::InputError("bmfr: workgroup must divide 1024 and be 8..512, got " + std::to_string(w));
  return w;
}

}  // namespace

BmfrFit::BmfrFit(gpu::Context& ctx, const BmfrOptions& options)
    : ctx_(&ctx),
      workgroup_(checked_workgroup(options)),
      pipeline_(ctx, {.shader = "recon_bmfr_fit.comp.spv",
                      .sets = {std::vector<gpu::Binding>(4, gpu::Binding::StorageBuffer)},
                      .push_constant_bytes = sizeof(shaders::ReconBmfrPush),
                      .specialization = {gpu::SpecConstant::u32(0, workgroup_),
                                         gpu::SpecConstant::boolean(1, options.precision == BmfrPrecision::Fp16)}}) {}

gpu::DescriptorSet BmfrFit::bind(const gpu::Buffer& vpos, const gpu::Buffer& vnrm, const gpu::Buffer& z,
                                 const gpu::Buffer& fitted) const {
  gpu::DescriptorSet set(*ctx_, pipeline_.set_layout(0));
  set.bind(0, vpos).bind(1, vnrm).bind(2, z).bind(3, fitted);
  return set;
}

void BmfrFit::record(VkCommandBuffer cmd, const gpu::DescriptorSet& set, BmfrGrid g, std::uint32_t frame,
                     glm::ivec2 offset, float noise) const {
  // One block of margin in each direction so a displaced block grid still covers the grid.
  const std::uint32_t bx = g.padded_columns / 32 + 1, by = g.padded_rows / 32 + 1;
  pipeline_.run(cmd, {&set},
                shaders::ReconBmfrPush{g.padded_columns, g.padded_rows, bx, frame, offset.x, offset.y, noise, 0},
                bx * by * workgroup_);
}

std::vector<glm::vec4> BmfrFit::fit(BmfrGrid g, const std::vector<glm::vec4>& vpos, const std::vector<glm::vec4>& vnrm,
                                    const std::vector<glm::vec4>& z, std::uint32_t frame, glm::ivec2 offset,
                                    float noise) const {
  const std::size_t cells = std::size_t(g.padded_columns) * g.padded_rows;
  if (g.padded_columns % 32 || g.padded_rows % 32 || cells == 0 || vpos.size() != cells || vnrm.size() != cells ||
      z.size() != cells)
    throw core::InputError("bmfr: inputs must cover a grid of whole 32x32 blocks");
  auto make = [&](const char* name) {
    return gpu::Buffer(*ctx_, {.size = cells * 16, .usage = gpu::BufferUsage::Storage,
                               .memory = gpu::Memory::HostVisible, .name = name});
  };
  gpu::Buffer bp = make("bmfr.vpos"), bn = make("bmfr.vnrm"), bz = make("bmfr.z"), out = make("bmfr.fitted");
  bp.upload(vpos);
  bn.upload(vnrm);
  bz.upload(z);
  const gpu::DescriptorSet set = bind(bp, bn, bz, out);
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { record(cmd, set, g, frame, offset, noise); });
  return out.download<glm::vec4>();
}

}  // namespace fovea::compositor
