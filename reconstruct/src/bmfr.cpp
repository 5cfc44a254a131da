// BMFR Phase II (shaders/recon_bmfr_fit.comp): the fit on its own (BmfrFit) and as a stage.
#include "fovea/reconstruct/bmfr.hpp"

#include <algorithm>
#include <string>

#include <glm/vec3.hpp>

#include "bindings.hpp"
#include "buffers.hpp"
#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/reconstruct/stages.hpp"
#include "fovea/shaders/grid_params.h"
#include "fovea/shaders/pt_scene.h"
#include "fovea/shaders/recon_grid.h"

namespace fovea::reconstruct {

namespace {

BmfrSchedule checked_schedule(const gpu::Context& ctx, const BmfrOptions& o) {
  const BmfrSchedule s = o.schedule ? *o.schedule : bmfr_schedule(ctx.info());
  if (s.workgroup < 8 || s.workgroup > 512 || 1024 % s.workgroup != 0)
    throw core::InputError("bmfr: workgroup must divide 1024 and be 8..512, got " + std::to_string(s.workgroup));
  if (s.reduction == BmfrReduction::Subgroup && !ctx.info().subgroup_arithmetic)
    throw core::InputError("bmfr: subgroup reductions need subgroup arithmetic in compute shaders, which " +
                           ctx.info().name + " does not have");
  return s;
}

}  // namespace

BmfrSchedule bmfr_schedule(const gpu::DeviceInfo& device) {
  if (device.type == VK_PHYSICAL_DEVICE_TYPE_CPU) return {8, BmfrReduction::Serial};
  return {256, device.subgroup_arithmetic ? BmfrReduction::Subgroup : BmfrReduction::Serial};
}

BmfrFit::BmfrFit(gpu::Context& ctx, const BmfrOptions& options)
    : ctx_(&ctx),
      schedule_(checked_schedule(ctx, options)),
      pipeline_(kernel<BmfrBindings, shaders::ReconBmfrPush>(
          ctx,
          schedule_.reduction == BmfrReduction::Subgroup ? "recon_bmfr_fit.subgroup.comp.spv"
                                                         : "recon_bmfr_fit.comp.spv",
          {gpu::SpecConstant::u32(0, schedule_.workgroup),
           gpu::SpecConstant::boolean(1, options.precision == BmfrPrecision::Fp16)})) {}

gpu::DescriptorSet BmfrFit::bind(const gpu::Buffer& vpos, const gpu::Buffer& vnrm, const gpu::Buffer& z,
                                 const gpu::Buffer& fitted, const gpu::Buffer& columns,
                                 const gpu::Buffer& materials, const gpu::Buffer& excess,
                                 const gpu::Buffer& edge) const {
  return make_set(*ctx_, pipeline_, BmfrBindings{&vpos, &vnrm, &z, &fitted, &columns, &materials, &excess, &edge});
}

void BmfrFit::record(VkCommandBuffer cmd, const gpu::DescriptorSet& set, BmfrGrid g, std::uint32_t frame,
                     glm::ivec2 offset, float noise) const {
  // One block of margin in each direction so a displaced block grid still covers the grid;
  // none in φ when the rows wrap (the displaced blocks cycle through each column's rows).
  const std::uint32_t bx = g.padded_columns / 32 + 1, by = g.padded_rows / 32 + (g.columns ? 0 : 1);
  pipeline_.run(cmd, {&set},
                shaders::ReconBmfrPush{g.padded_columns, g.padded_rows, bx, frame, offset.x, offset.y, noise, g.columns},
                bx * by * schedule_.workgroup);
}

std::vector<glm::vec4> BmfrFit::fit(BmfrGrid g, const std::vector<glm::vec4>& vpos, const std::vector<glm::vec4>& vnrm,
                                    const std::vector<glm::vec4>& z, std::uint32_t frame, glm::ivec2 offset,
                                    float noise, const std::vector<std::uint32_t>& rows,
                                    const std::vector<bool>& metal, const std::vector<std::uint32_t>& edge) const {
  const std::size_t cells = std::size_t(g.padded_columns) * g.padded_rows;
  if (g.padded_columns % 32 || g.padded_rows % 32 || cells == 0 || vpos.size() != cells || vnrm.size() != cells ||
      z.size() != cells || (!edge.empty() && edge.size() != cells))
    throw core::InputError("bmfr: inputs must cover a grid of whole 32x32 blocks");
  if (rows.size() != g.columns || g.columns > g.padded_columns)
    throw core::InputError("bmfr: need one row count per column of a polar grid (" + std::to_string(g.columns) +
                           "), got " + std::to_string(rows.size()));
  std::vector<shaders::GridColumn> table(std::max<std::size_t>(rows.size(), 1));
  for (std::size_t c = 0; c < rows.size(); ++c) {
    if (rows[c] > g.padded_rows)
      throw core::InputError("bmfr: column " + std::to_string(c) + " has more rows than the grid");
    table[c].rows = rows[c];
  }
  auto make = [&](const char* name) {  // RGBA32F texels: the fit reads its inputs with texelFetch
    return gpu::Buffer(*ctx_, {.size = cells * 16, .usage = gpu::BufferUsage::Storage,
                               .memory = gpu::Memory::HostVisible, .name = name,
                               .texel_format = VK_FORMAT_R32G32B32A32_SFLOAT});
  };
  gpu::Buffer bp = make("bmfr.vpos"), bn = make("bmfr.vnrm"), bz = make("bmfr.z"), out = make("bmfr.fitted"),
              ex = make("bmfr.excess");
  gpu::Buffer bt(*ctx_, {.size = table.size() * sizeof(shaders::GridColumn), .usage = gpu::BufferUsage::Storage,
                         .memory = gpu::Memory::HostVisible, .name = "bmfr.columns"});
  shaders::PtMaterial white{};
  white.base_r = white.base_g = white.base_b = 1.0f;
  white.texture = -1;
  std::vector<shaders::PtMaterial> materials(std::max<std::size_t>(metal.size(), 1), white);
  for (std::size_t m = 0; m < metal.size(); ++m) materials[m].metallic = metal[m] ? 1.0f : 0.0f;
  gpu::Buffer bm(*ctx_, {.size = materials.size() * sizeof(shaders::PtMaterial), .usage = gpu::BufferUsage::Storage,
                         .memory = gpu::Memory::HostVisible, .name = "bmfr.materials"});
  gpu::Buffer be(*ctx_, {.size = cells * 4, .usage = gpu::BufferUsage::Storage, .memory = gpu::Memory::HostVisible,
                         .name = "bmfr.edge", .texel_format = VK_FORMAT_R32_UINT});
  be.upload(edge.empty() ? std::vector<std::uint32_t>(cells, 0u) : edge);
  bp.upload(vpos);
  bn.upload(vnrm);
  bz.upload(z);
  bt.upload(table);
  bm.upload(materials);
  const gpu::DescriptorSet set = bind(bp, bn, bz, out, bt, bm, ex, be);
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { record(cmd, set, g, frame, offset, noise); });
  std::vector<glm::vec4> fitted = out.download<glm::vec4>();
  const std::vector<glm::vec4> excess = ex.download<glm::vec4>();
  for (std::size_t i = 0; i < cells; ++i) fitted[i] += glm::vec4(glm::vec3(excess[i]), 0.0f);
  return fitted;
}

glm::ivec2 bmfr_block_offset(std::uint32_t frame) {
  // A 4×4 stratification of [0, 32)² (one offset per 8×8 stratum, visited in a shuffled
  // order with fixed sub-stratum positions): uniform over all offsets and fixed.
  static constexpr int kOrder[16] = {5, 14, 3, 8, 11, 0, 13, 6, 2, 9, 15, 4, 10, 7, 1, 12};
  static constexpr int kJitter[16][2] = {{3, 5}, {6, 1}, {1, 6}, {4, 3}, {7, 7}, {2, 2}, {5, 4}, {0, 0},
                                         {6, 5}, {3, 1}, {1, 3}, {5, 7}, {2, 6}, {7, 2}, {4, 0}, {0, 4}};
  const int s = kOrder[frame % 16];
  return {(s % 4) * 8 + kJitter[s][0], (s / 4) * 8 + kJitter[s][1]};
}

}  // namespace fovea::reconstruct

namespace fovea::reconstruct {

Bmfr::Bmfr(gpu::Context& ctx, std::span<const EyeGrid> eyes, const Accumulation& acc, const StereoGather& gather,
           const gpu::Buffer& materials, BmfrPrecision precision)
    : fit_(ctx, {.precision = precision}), eyes_(eyes.size()) {
  for (std::size_t i = 0; i < eyes.size(); ++i) {
    Eye& e = eyes_[i];
    e.grid = {eyes[i].padded_columns, eyes[i].padded_rows, eyes[i].polar ? eyes[i].columns : 0};
    e.fitted = cells(ctx, eyes[i].cells, "recon.fitted");
    e.excess = cells(ctx, eyes[i].cells, "recon.excess");
    for (int p = 0; p < 2; ++p)
      e.set[p] = fit_.bind(acc.position(int(i), p), acc.normal(int(i), p), gather.shared(int(i)), e.fitted,
                           *eyes[i].tables(), materials, e.excess, gather.edge(int(i)));
  }
}

void Bmfr::record(VkCommandBuffer cmd, int parity, std::uint32_t frame, glm::ivec2 offset, float noise) const {
  for (const Eye& e : eyes_) fit_.record(cmd, e.set[parity], e.grid, frame, offset, noise);
  gpu::compute_to_compute(cmd);
}

void Bmfr::fill(VkCommandBuffer cmd, std::uint32_t word) const {
  for (const Eye& e : eyes_) {
    gpu::fill_buffer(cmd, e.fitted, word);
    gpu::fill_buffer(cmd, e.excess, word);
  }
}

}  // namespace fovea::reconstruct
