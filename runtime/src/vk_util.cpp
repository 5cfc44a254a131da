#include "vk_util.hpp"

#include <stdexcept>
#include <string>

#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/memory_type.hpp"

namespace fovea::runtime {

void vk_check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed (VkResult " + std::to_string(r) + ")");
}

std::uint32_t find_memory_type(VkPhysicalDevice physical, std::uint32_t type_bits, VkMemoryPropertyFlags flags) {
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical, &mp);
  const auto type = gpu::find_memory_type(mp, type_bits, flags);
  if (!type) throw std::runtime_error("no suitable Vulkan memory type");
  return *type;
}

void transition(VkCommandBuffer cmd, VkImage image, bool depth, VkImageLayout from, VkImageLayout to,
                VkAccessFlags src_access, VkAccessFlags dst_access, VkPipelineStageFlags src_stage,
                VkPipelineStageFlags dst_stage) {
  const VkImageMemoryBarrier b = gpu::image_barrier_info(
      image, from, to, src_access, dst_access,
      {VkImageAspectFlags(depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT), 0, VK_REMAINING_MIP_LEVELS, 0,
       VK_REMAINING_ARRAY_LAYERS});
  vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

}  // namespace fovea::runtime
