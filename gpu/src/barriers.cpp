#include "fovea/gpu/barriers.hpp"

namespace fovea::gpu {
namespace {
// An empty side of a barrier (e.g. "nothing before" for a fresh image) still needs a stage.
VkPipelineStageFlags src_stage(Access a) { return a.stage != 0 ? a.stage : VkPipelineStageFlags{VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT}; }
VkPipelineStageFlags dst_stage(Access a) {
  return a.stage != 0 ? a.stage : VkPipelineStageFlags{VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT};
}
}  // namespace

void barrier(VkCommandBuffer cmd, Access src, Access dst) {
  VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  b.srcAccessMask = src.access;
  b.dstAccessMask = dst.access;
  vkCmdPipelineBarrier(cmd, src_stage(src),
                       dst_stage(dst), 0, 1, &b, 0, nullptr, 0, nullptr);
}

VkImageMemoryBarrier image_barrier_info(VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags src,
                                        VkAccessFlags dst, VkImageSubresourceRange range) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = src;
  b.dstAccessMask = dst;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = range;
  return b;
}

void image_barrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to, Access src, Access dst) {
  const VkImageMemoryBarrier b = image_barrier_info(image, from, to, src.access, dst.access);
  vkCmdPipelineBarrier(cmd, src_stage(src), dst_stage(dst), 0, 0, nullptr, 0, nullptr, 1, &b);
}

}  // namespace fovea::gpu
