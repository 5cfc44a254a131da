#include "fovea/gpu/foreign_queue.hpp"

#include <stdexcept>

namespace fovea::gpu {

ForeignQueue::ForeignQueue(VkDevice device, PFN_vkGetDeviceProcAddr get_device_proc, std::uint32_t family,
                           VkQueue queue, std::uint64_t timeout_ns, std::string device_name)
    : device_(device), queue_(queue), timeout_ns_(timeout_ns), device_name_(std::move(device_name)) {
  if (!get_device_proc || !device_ || !queue_) throw std::runtime_error("no device or queue to submit to on " + device_name_);
#define FOVEA_FOREIGN_VK_LOAD(name)                                                                  \
  name##_ = reinterpret_cast<PFN_##name>(get_device_proc(device_, #name));                           \
  if (!name##_) throw std::runtime_error(device_name_ + " does not resolve " #name);
  FOVEA_FOREIGN_VK(FOVEA_FOREIGN_VK_LOAD)
#undef FOVEA_FOREIGN_VK_LOAD
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = family;
  check(vkCreateCommandPool_(device_, &pci, nullptr, &pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  try {
    check(vkAllocateCommandBuffers_(device_, &ai, &cmd_), "vkAllocateCommandBuffers");
    check(vkCreateFence_(device_, &fci, nullptr, &fence_), "vkCreateFence");
  } catch (...) {
    destroy();
    throw;
  }
}

ForeignQueue::~ForeignQueue() {
  // The command buffer must not be pending when its pool goes; a failed wait leaves nothing better to do.
  if (pending_) vkWaitForFences_(device_, 1, &fence_, VK_TRUE, timeout_ns_);
  destroy();
}

void ForeignQueue::destroy() {
  if (fence_) vkDestroyFence_(device_, fence_, nullptr);
  if (pool_) vkDestroyCommandPool_(device_, pool_, nullptr);  // frees the command buffer
  fence_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
}

void ForeignQueue::check(VkResult r, const char* what) const {
  if (r != VK_SUCCESS)
    throw std::runtime_error(std::string(what) + " failed on " + device_name_ + ": VkResult " + std::to_string(int(r)));
}

void ForeignQueue::run(const std::function<void(VkCommandBuffer)>& record) {
  submit(record);
  wait();
}

void ForeignQueue::submit(const std::function<void(VkCommandBuffer)>& record) {
  wait();
  check(vkResetCommandBuffer_(cmd_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer_(cmd_, &bi), "vkBeginCommandBuffer");
  record(cmd_);
  check(vkEndCommandBuffer_(cmd_), "vkEndCommandBuffer");
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd_;
  check(vkResetFences_(device_, 1, &fence_), "vkResetFences");
  check(vkQueueSubmit_(queue_, 1, &si, fence_), "vkQueueSubmit");
  pending_ = true;
}

void ForeignQueue::wait() {
  if (!pending_) return;
  const VkResult w = vkWaitForFences_(device_, 1, &fence_, VK_TRUE, timeout_ns_);
  if (w == VK_TIMEOUT)
    throw std::runtime_error("a submission did not finish on " + device_name_ + " in " +
                             std::to_string(timeout_ns_ / 1'000'000) + " ms");
  check(w, "vkWaitForFences");
  pending_ = false;
}

}  // namespace fovea::gpu
