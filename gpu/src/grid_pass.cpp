#include "fovea/gpu/grid_pass.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "fovea/core/distribution.hpp"
#include "fovea/gpu/context.hpp"

namespace fovea::gpu {

namespace {
Buffer host_buffer(Context& ctx, VkDeviceSize bytes, BufferUsage usage, const char* name) {
  return Buffer(ctx, {.size = std::max<VkDeviceSize>(bytes, 16), .usage = usage, .memory = Memory::HostVisible, .name = name});
}
}  // namespace

GridPass::GridPass(Context& ctx)
    : ctx_(&ctx),
      pipeline_(ctx, {.shader = "grid_generate.comp.spv",
                      .sets = {{Binding::UniformBuffer, Binding::StorageBuffer, Binding::StorageBuffer,
                                Binding::StorageBuffer, Binding::StorageBuffer}}}),
      params_(host_buffer(ctx, sizeof(shaders::GridParams), BufferUsage::Uniform, "grid params")),
      columns_(host_buffer(ctx, 16, BufferUsage::Storage, "grid columns")),
      mask_(host_buffer(ctx, 16, BufferUsage::Storage, "hidden mask")),
      counts_(host_buffer(ctx, 2 * sizeof(std::uint32_t), BufferUsage::Storage, "grid counts")),
      set_(ctx, pipeline_.set_layout(0)) {
  set_.bind(0, params_).bind(1, columns_).bind(2, mask_).bind(4, counts_);
}

VkDeviceSize GridPass::samples_bytes(const core::SampleDistribution& d) {
  return VkDeviceSize(d.padded_columns()) * VkDeviceSize(d.padded_rows()) * sizeof(shaders::GridSample);
}

void GridPass::prepare(const core::SampleDistribution& d, std::span<const std::uint32_t> hidden_mask) {
  shaders::GridParams p = d.gpu_params();
  const auto& table = d.column_table();
  const VkDeviceSize table_bytes = table.size() * sizeof(shaders::GridColumn);
  if (table_bytes > columns_.size()) {
    columns_ = host_buffer(*ctx_, table_bytes, BufferUsage::Storage, "grid columns");
    set_.bind(1, columns_);
  }
  if (!table.empty()) columns_.upload(table);
  if (!hidden_mask.empty()) {
    const VkDeviceSize need = VkDeviceSize(d.view().width() + 31) / 32 * 4 * VkDeviceSize(d.view().height());
    if (hidden_mask.size_bytes() < need) throw std::invalid_argument("hidden mask smaller than the view raster");
    if (hidden_mask.size_bytes() > mask_.size()) {
      mask_ = host_buffer(*ctx_, hidden_mask.size_bytes(), BufferUsage::Storage, "hidden mask");
      set_.bind(2, mask_);
    }
    mask_.upload(hidden_mask);
    p.has_mask = 1.0f;
  }
  params_.upload(std::span(&p, 1));
  // Host writes to coherent memory are visible to the next submission.
  const std::uint32_t zero[2] = {0, 0};
  counts_.upload(std::span(zero));
  padded_columns_ = p.padded_columns;
  padded_rows_ = p.padded_rows;
}

void GridPass::record(VkCommandBuffer cmd, const Buffer& samples) {
  if (samples.size() < VkDeviceSize(padded_columns_) * padded_rows_ * sizeof(shaders::GridSample))
    throw std::invalid_argument("grid samples buffer too small for the grid");
  if (bound_samples_ != samples.handle()) {
    set_.bind(3, samples);
    bound_samples_ = samples.handle();
  }
  pipeline_.bind(cmd, {&set_});
  pipeline_.dispatch(cmd, padded_columns_, padded_rows_);
}

GridPass::Counts GridPass::counts() const {
  std::uint32_t c[2];
  std::memcpy(c, counts_.mapped().data(), sizeof(c));
  return {c[0], c[1]};
}

void GridPass::generate(const core::SampleDistribution& d, const Buffer& samples,
                        std::span<const std::uint32_t> hidden_mask) {
  prepare(d, hidden_mask);
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { record(cmd, samples); });
}

}  // namespace fovea::gpu
