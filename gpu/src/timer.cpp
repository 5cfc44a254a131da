#include "fovea/gpu/timer.hpp"

#include <cmath>
#include <stdexcept>

#include "fovea/gpu/context.hpp"
#include "fovea/gpu/error.hpp"

namespace fovea::gpu {

std::int64_t ticks_to_ns(std::uint64_t a, std::uint64_t b, std::uint32_t valid_bits, double period_ns) {
  const std::uint64_t mask = valid_bits >= 64 ? ~0ull : (1ull << valid_bits) - 1;
  const std::uint64_t ticks = ((b & mask) - (a & mask)) & mask;  // modular: survives one wrap
  return static_cast<std::int64_t>(std::llround(static_cast<double>(ticks) * period_ns));
}

GpuTimer::GpuTimer(Context& ctx, std::uint32_t max_stages)
    : valid_bits_(ctx.info().timestamp_valid_bits), period_ns_(ctx.info().timestamp_period_ns), max_stages_(max_stages) {
  if (!ctx.timestamps_supported()) return;
  VkQueryPoolCreateInfo ci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  ci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  ci.queryCount = max_stages + 1;
  VkQueryPool pool = VK_NULL_HANDLE;
  check(vkCreateQueryPool(ctx.device(), &ci, nullptr, &pool), "vkCreateQueryPool");
  pool_ = {ctx.device(), pool};
}

void GpuTimer::begin(VkCommandBuffer cmd) {
  names_.clear();
  begun_ = true;
  if (!pool_) return;
  vkCmdResetQueryPool(cmd, pool_.get(), 0, max_stages_ + 1);
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_.get(), 0);
}

void GpuTimer::stage(VkCommandBuffer cmd, std::string name) {
  if (!begun_) throw std::logic_error("gpu::GpuTimer::stage before begin");
  if (names_.size() >= max_stages_)
    throw std::length_error("gpu::GpuTimer: more than " + std::to_string(max_stages_) + " stages");
  names_.push_back(std::move(name));
  if (!pool_) return;
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_.get(), static_cast<std::uint32_t>(names_.size()));
}

std::optional<std::vector<StageTime>> GpuTimer::read() const {
  if (!pool_) return std::nullopt;
  if (!begun_) throw std::logic_error("gpu::GpuTimer::read before begin");
  std::vector<std::uint64_t> ticks(names_.size() + 1);
  check(vkGetQueryPoolResults(pool_.device(), pool_.get(), 0, static_cast<std::uint32_t>(ticks.size()),
                              ticks.size() * sizeof(std::uint64_t), ticks.data(), sizeof(std::uint64_t),
                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");
  std::vector<StageTime> stages;
  for (std::size_t i = 0; i < names_.size(); ++i)
    stages.push_back({names_[i], ticks_to_ns(ticks[0], ticks[i], valid_bits_, period_ns_),
                      ticks_to_ns(ticks[0], ticks[i + 1], valid_bits_, period_ns_)});
  return stages;
}

}  // namespace fovea::gpu
