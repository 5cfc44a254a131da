#pragma once
// Small Vulkan helpers on the application's device: one-shot command submission on the
// session's queue (used only inside the calls where OpenXR lets the runtime use that queue:
// xrAcquireSwapchainImage, xrReleaseSwapchainImage, xrBeginFrame, xrEndFrame) and memory
// type selection.
#include <cstdint>
#include <functional>

#include <vulkan/vulkan.h>

namespace fovea::runtime {

class OneShotQueue {
 public:
  OneShotQueue(VkDevice device, std::uint32_t family, VkQueue queue);
  ~OneShotQueue();
  OneShotQueue(const OneShotQueue&) = delete;
  OneShotQueue& operator=(const OneShotQueue&) = delete;
  // Records with `record`, submits, waits for completion. Throws std::runtime_error on a
  // Vulkan failure.
  void run(const std::function<void(VkCommandBuffer)>& record);

 private:
  VkDevice device_;
  VkQueue queue_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
};

// Index of a memory type allowed by `type_bits` with all of `flags`; throws if none.
std::uint32_t find_memory_type(VkPhysicalDevice physical, std::uint32_t type_bits, VkMemoryPropertyFlags flags);
void vk_check(VkResult r, const char* what);

// A whole-image layout transition (colour or depth aspect, all mips and layers).
void transition(VkCommandBuffer cmd, VkImage image, bool depth, VkImageLayout from, VkImageLayout to,
                VkAccessFlags src_access, VkAccessFlags dst_access, VkPipelineStageFlags src_stage,
                VkPipelineStageFlags dst_stage);

}  // namespace fovea::runtime
