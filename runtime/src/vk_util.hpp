#pragma once
// Small Vulkan helpers on the application's device: one-shot command submission on the
// session's queue (used only inside the calls where OpenXR lets the runtime use that queue:
// xrAcquireSwapchainImage, xrReleaseSwapchainImage, xrBeginFrame, xrEndFrame) and memory
// type selection.
#include <cstdint>

#include <vulkan/vulkan.h>

#include "fovea/gpu/foreign_queue.hpp"

namespace fovea::runtime {

// The session queue's one-shot submit-and-wait (xrcommon's), waiting without a bound as the
// application's own submissions would.
class OneShotQueue : public gpu::ForeignQueue {
 public:
  OneShotQueue(VkDevice device, std::uint32_t family, VkQueue queue)
      : ForeignQueue(device, &vkGetDeviceProcAddr, family, queue, kNoTimeout, "the application's device") {}
};

// Index of a memory type allowed by `type_bits` with all of `flags`; throws if none.
std::uint32_t find_memory_type(VkPhysicalDevice physical, std::uint32_t type_bits, VkMemoryPropertyFlags flags);
void vk_check(VkResult r, const char* what);

// A whole-image layout transition (colour or depth aspect, all mips and layers).
void transition(VkCommandBuffer cmd, VkImage image, bool depth, VkImageLayout from, VkImageLayout to,
                VkAccessFlags src_access, VkAccessFlags dst_access, VkPipelineStageFlags src_stage,
                VkPipelineStageFlags dst_stage);

}  // namespace fovea::runtime
