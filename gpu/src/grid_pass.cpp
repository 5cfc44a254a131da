#include "fovea/gpu/grid_pass.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "fovea/core/distribution.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/shaders/grid_bindings.h"
#include "fovea/shaders/live_cells.h"
#include "fovea/shaders/pt_order.h"

namespace fovea::gpu {

namespace {
// Written by the host each frame and read by every cell's invocation (the counts: zeroed by
// the host, added to by one atomic per subgroup, read back once): device-local where the
// device can map such memory.
Buffer host_buffer(Context& ctx, VkDeviceSize bytes, BufferUsage usage, const char* name) {
  return Buffer(ctx,
                {.size = std::max<VkDeviceSize>(bytes, 16), .usage = usage, .memory = Memory::Upload, .name = name});
}
}  // namespace

GridPass::GridPass(Context& ctx, std::uint32_t cells, bool ballot)
    : ctx_(&ctx),
      pipeline_(ctx, {.shader = ballot && ctx.info().subgroup_ballot ? "grid_generate.comp.spv"
                                                                     : "grid_generate.noballot.comp.spv",
                      .sets = {{Binding::UniformBuffer, Binding::StorageBuffer, Binding::StorageBuffer,
                                Binding::StorageBuffer, Binding::StorageBuffer, Binding::StorageBuffer,
                                Binding::StorageBuffer}}}),
      list_pipeline_(ctx, {.shader = "grid_live_list.comp.spv",
                           .sets = {{Binding::StorageBuffer, Binding::StorageBuffer, Binding::StorageBuffer}},
                           .push_constant_bytes = sizeof(std::uint32_t)}),
      params_(host_buffer(ctx, sizeof(shaders::GridParams), BufferUsage::Uniform, "grid params")),
      columns_(host_buffer(ctx, 16, BufferUsage::Storage, "grid columns")),
      mask_(host_buffer(ctx, 16, BufferUsage::Storage, "hidden mask")),
      counts_(host_buffer(ctx, sizeof(shaders::GridCounts), BufferUsage::Storage, "grid counts")),
      set_(ctx, pipeline_.set_layout(0)),
      list_set_(ctx, list_pipeline_.set_layout(0)) {
  set_.bind(GRID_BINDING_PARAMS, params_).bind(GRID_BINDING_COLUMNS, columns_).bind(GRID_BINDING_MASK, mask_);
  set_.bind(GRID_BINDING_COUNTS, counts_);
  list_set_.bind(LIVE_LIST_BINDING_COUNTS, counts_);
  reserve(std::max<std::uint32_t>(cells, 1));
}

void GridPass::reserve(std::uint32_t cells) {
  if (cells <= capacity_ * shaders::kLiveTileCells) return;
  capacity_ = (cells + shaders::kLiveTileCells - 1) / shaders::kLiveTileCells;  // tiles
  list_ = Buffer(*ctx_, {.size = (VkDeviceSize(shaders::kLiveHeaderWords) + capacity_) * sizeof(std::uint32_t),
                         .usage = BufferUsage::Storage | BufferUsage::Indirect,
                         .name = "grid live cells"});
  history_ = Buffer(*ctx_, {.size = VkDeviceSize(capacity_) * shaders::kLiveTileCells * sizeof(std::uint32_t),
                            .name = "grid live history"});
  tile_state_ = Buffer(*ctx_, {.size = VkDeviceSize(capacity_) * sizeof(std::uint32_t), .name = "grid tile state"});
  set_.bind(GRID_BINDING_HISTORY, history_).bind(GRID_BINDING_TILE_STATE, tile_state_);
  list_set_.bind(LIVE_LIST_BINDING_LIST, list_).bind(LIVE_LIST_BINDING_TILE_STATE, tile_state_);
  history_fresh_ = true;
}

VkDeviceSize GridPass::samples_bytes(const core::SampleDistribution& d) {
  return VkDeviceSize(d.padded_columns()) * VkDeviceSize(d.padded_rows()) * sizeof(shaders::GridSample);
}

void GridPass::prepare(const core::SampleDistribution& d, std::span<const std::uint32_t> hidden_mask) {
  shaders::GridParams p = d.gpu_params();
  if (p.padded_columns % shaders::kPtTileColumns != 0 || p.padded_rows % shaders::kPtTileRows != 0)
    throw std::invalid_argument("grid pass: padded grid of " + std::to_string(p.padded_columns) + "x" +
                                std::to_string(p.padded_rows) + " cells is not whole tiles");
  reserve(p.padded_columns * p.padded_rows);
  const auto& table = d.column_table();
  const VkDeviceSize table_bytes = table.size() * sizeof(shaders::GridColumn);
  if (table_bytes > columns_.size()) {
    columns_ = host_buffer(*ctx_, table_bytes, BufferUsage::Storage, "grid columns");
    set_.bind(GRID_BINDING_COLUMNS, columns_);
  }
  if (!table.empty()) columns_.upload(table);
  if (!hidden_mask.empty()) {
    const VkDeviceSize need = VkDeviceSize(d.view().width() + 31) / 32 * 4 * VkDeviceSize(d.view().height());
    if (hidden_mask.size_bytes() < need) throw std::invalid_argument("hidden mask smaller than the view raster");
    if (hidden_mask.size_bytes() > mask_.size()) {
      mask_ = host_buffer(*ctx_, hidden_mask.size_bytes(), BufferUsage::Storage, "hidden mask");
      set_.bind(GRID_BINDING_MASK, mask_);
    }
    mask_.upload(hidden_mask);
    p.has_mask = 1.0f;
  }
  params_.upload(std::span(&p, 1));
  // Host writes to coherent memory are visible to the next submission.
  shaders::GridCounts zero{};
  zero.tiles_across = p.padded_columns / shaders::kPtTileColumns;
  zero.tiles = zero.tiles_across * (p.padded_rows / shaders::kPtTileRows);
  counts_.upload(std::span(&zero, 1));
  padded_columns_ = p.padded_columns;
  padded_rows_ = p.padded_rows;
}

void GridPass::record(VkCommandBuffer cmd, const Buffer& samples) {
  if (samples.size() < VkDeviceSize(padded_columns_) * padded_rows_ * sizeof(shaders::GridSample))
    throw std::invalid_argument("grid samples buffer too small for the grid");
  if (bound_samples_ != samples.handle()) {
    set_.bind(GRID_BINDING_SAMPLES, samples);
    bound_samples_ = samples.handle();
  }
  if (history_fresh_) {
    fill_buffer(cmd, history_, shaders::kLiveAllBefore);
    fill_buffer(cmd, tile_state_, 0);  // after a new allocation; grid_live_list.comp leaves it zero
    transfer_to_compute(cmd);
    history_fresh_ = false;
  }
  pipeline_.bind(cmd, {&set_});
  // A workgroup per tile: 2-D group counts stay within the device's limits for 8k rasters.
  pipeline_.dispatch(cmd, padded_columns_ / shaders::kPtTileColumns * pipeline_.workgroup_size()[0],
                     padded_rows_ / shaders::kPtTileRows);
  compute_to_compute(cmd);
  list_pipeline_.run(cmd, {&list_set_}, ctx_->limits().maxComputeWorkGroupCount[0], 1);
}

GridPass::Counts GridPass::counts() const {
  shaders::GridCounts c;
  std::memcpy(&c, counts_.mapped().data(), sizeof(c));
  return {c.live, c.hidden, c.reset};
}

void GridPass::generate(const core::SampleDistribution& d, const Buffer& samples,
                        std::span<const std::uint32_t> hidden_mask) {
  prepare(d, hidden_mask);
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { record(cmd, samples); });
}

}  // namespace fovea::gpu
