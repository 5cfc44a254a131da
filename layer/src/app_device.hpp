#pragma once
// Transfers between host memory and images on the application's VkDevice, on the
// session's queue (the queue the runtime also uses; the layer submits only inside
// xrEndFrame, before calling down). Each transfer is one submission and a bounded fence wait,
// under no lock another application call needs.
#include <cstdint>
#include <memory>
#include <vector>

#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>

#include "composite.hpp"
#include "fovea/xrcommon/foreign_queue.hpp"
#include "frame_renderer.hpp"

namespace fovea::layer {

// D16_UNORM, X8_D24_UNORM_PACK32, D24_UNORM_S8_UINT, D32_SFLOAT, D32_SFLOAT_S8_UINT.
bool depth_format_supported(VkFormat f);

class AppDevice {
 public:
  explicit AppDevice(const VulkanBinding& vk);  // throws std::runtime_error
  ~AppDevice();
  AppDevice(const AppDevice&) = delete;
  AppDevice& operator=(const AppDevice&) = delete;

  struct Read {
    VkImage image;
    std::uint32_t array_layer;
    XrRect2Di rect;
  };
  // Reads 4-byte texels of each image's rect (images in COLOR_ATTACHMENT_OPTIMAL, left so).
  std::vector<Pixels8> read(const std::vector<Read>& reads);
  // Reads the depth aspect of each depth image's rect (images in
  // DEPTH_STENCIL_ATTACHMENT_OPTIMAL, left so) as window depths in [0, 1], row-major.
  // Throws std::runtime_error for a format without a decoding (depth_format_supported).
  std::vector<std::vector<float>> read_depth(const std::vector<AppDepth>& reads);
  // Overwrites each whole image (array layer 0) with `pixels` (same size); the images end in
  // COLOR_ATTACHMENT_OPTIMAL.
  void write(const std::vector<VkImage>& images, const std::vector<const Pixels8*>& pixels);

 private:
  struct HostBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
    VkDeviceSize size = 0;
  };
  void reserve(HostBuffer& b, VkDeviceSize size, VkBufferUsageFlags usage);
  void release(HostBuffer& b);
  // One region of an attachment image copied into download_ at `offset`: transition to
  // TRANSFER_SRC after the application's writes, copy `copy_aspect`, transition back.
  struct Download {
    VkImage image;
    std::uint32_t array_layer;
    VkImageLayout attachment_layout;
    VkAccessFlags attachment_writes;
    VkImageAspectFlags aspects;  // every aspect of the image, for the layout transitions
    VkImageAspectFlags copy_aspect;
    XrRect2Di rect;
    VkDeviceSize offset;
  };
  void record_download(VkCommandBuffer cb, const Download& d);
  void record_host_read_barrier(VkCommandBuffer cb);

  VkDevice device_ = VK_NULL_HANDLE;
  std::unique_ptr<xrcommon::ForeignQueue> queue_;  // the session queue, bounded waits
  HostBuffer download_, upload_;
  VkPhysicalDeviceMemoryProperties memory_{};

#define FOVEA_APP_VK(X)                                                                                          \
  X(vkGetDeviceQueue) X(vkCmdPipelineBarrier) X(vkCmdCopyImageToBuffer) X(vkCmdCopyBufferToImage)             \
  X(vkCreateBuffer) X(vkDestroyBuffer) X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory)     \
  X(vkBindBufferMemory) X(vkMapMemory) X(vkUnmapMemory)
#define FOVEA_APP_VK_MEMBER(name) PFN_##name name##_ = nullptr;
  FOVEA_APP_VK(FOVEA_APP_VK_MEMBER)
#undef FOVEA_APP_VK_MEMBER
};

}  // namespace fovea::layer
