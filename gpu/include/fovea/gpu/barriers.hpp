#pragma once
// Pipeline barriers. Within one command buffer every dependency between dispatches and
// transfers needs one of these; submit_and_wait already orders whole submissions
// against each other and against host reads.
#include <cstdint>

#include <vulkan/vulkan_core.h>

namespace fovea::gpu {

// A pipeline stage and the memory accesses made there.
struct Access {
  VkPipelineStageFlags stage = 0;
  VkAccessFlags access = 0;
};
constexpr Access operator|(Access a, Access b) { return {a.stage | b.stage, a.access | b.access}; }

namespace access {
inline constexpr Access compute_read{VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT};
inline constexpr Access compute_write{VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT};
inline constexpr Access transfer_read{VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT};
inline constexpr Access transfer_write{VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT};
inline constexpr Access indirect_read{VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, VK_ACCESS_INDIRECT_COMMAND_READ_BIT};
inline constexpr Access host_read{VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT};
inline constexpr Access host_write{VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_WRITE_BIT};
inline constexpr Access all_write{VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT};
inline constexpr Access all{VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT};
}  // namespace access

// Global memory barrier: accesses `src` made before happen-before accesses `dst` after.
void barrier(VkCommandBuffer cmd, Access src, Access dst);

// The usual ones, spelled out.
inline void compute_to_compute(VkCommandBuffer cmd) {
  barrier(cmd, access::compute_write, access::compute_read | access::compute_write);
}
// Also for the arguments of indirect dispatches the earlier shaders wrote.
inline void compute_to_indirect(VkCommandBuffer cmd) {
  barrier(cmd, access::compute_write, access::compute_read | access::compute_write | access::indirect_read);
}
inline void transfer_to_compute(VkCommandBuffer cmd) {
  barrier(cmd, access::transfer_write, access::compute_read | access::compute_write);
}
inline void compute_to_transfer(VkCommandBuffer cmd) {
  barrier(cmd, access::compute_write, access::transfer_read | access::transfer_write);
}

// The subresources of a colour image's first mip in array layer `layer`.
constexpr VkImageSubresourceRange colour_layer(std::uint32_t layer = 0) {
  return {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, layer, 1};
}

// An image memory barrier with a layout transition, as a struct: for command buffers recorded
// through a device's own function table (the application's device, in the layer and the
// runtime) or with several barriers in one call.
VkImageMemoryBarrier image_barrier_info(VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags src,
                                        VkAccessFlags dst, VkImageSubresourceRange range = colour_layer());

// Image memory barrier with a layout transition (whole colour image, one mip, one layer).
// Fovea's own images stay in VK_IMAGE_LAYOUT_GENERAL; this is for images handed over
// to or from other APIs (OpenXR swapchains) and for sampling-only layouts.
void image_barrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to, Access src, Access dst);

}  // namespace fovea::gpu
