#pragma once
// The layer's work on the application's VkDevice, on the session's queue (the queue the
// runtime also uses; the layer submits only inside xrEndFrame, before calling down):
// transfers between host memory and its images (the host composition), or the composition
// as a compute pass there (the GPU composition). Each is one submission and a bounded fence
// wait, under no lock another application call needs.
#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>

#include "composite.hpp"
#include "fovea/xrcommon/foreign_queue.hpp"
#include "frame_renderer.hpp"

namespace fovea::layer {

// Throws std::runtime_error naming the call unless r is VK_SUCCESS.
void app_check(VkResult r, const char* what);

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
  // How many read() and read_depth() calls copied application images to the host.
  std::int64_t host_readbacks() const { return host_readbacks_; }

  // Composition on this device (gpu_composite.cpp), without the host round trip: prepares the
  // compute pass on the session queue; throws std::runtime_error with the reason when the
  // device cannot run it (the session queue's family has no compute, no memory type).
  void enable_gpu_composition();
  bool gpu_composition() const { return gpu_ != nullptr; }
  struct GpuEye {
    // `traced` (and `traced_depth`) are uploaded only when `traced_id` changed; `app` and
    // `app_depth` unused (the images below are read on the device).
    EyeComposition composition;
    Read app;                      // the application's projection view (unused in scene-only mode)
    std::optional<AppDepth> depth;  // its depth, when compositing by depth (with composition.traced_depth)
    VkImage target;                // written whole (out_view's raster), ends in COLOR_ATTACHMENT_OPTIMAL
  };
  // One submission on the session queue, not waited for: it uploads the traced frame if new,
  // copies the application's rects (and depth rects) into device buffers, runs the
  // composition pass and copies the results into the targets. Later work on the queue (the
  // application's next rendering into its images, the runtime's reads) comes after it; the
  // next call first waits for it.
  void composite_gpu(std::int64_t traced_id, const std::array<GpuEye, 2>& eyes, const CompositionRule& rule);
  // Waits for a composition pass still running (before the images it reads or writes are
  // destroyed: the application's swapchains, the targets).
  void finish();

 private:
  struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;  // host-visible buffers only
    VkDeviceSize size = 0;
  };
  // At least `size` bytes: host-visible and coherent (mapped), or device-local when `host` is false.
  void reserve(Buffer& b, VkDeviceSize size, VkBufferUsageFlags usage, bool host = true);
  void release(Buffer& b);
  // One region of an attachment image copied into `buffer` at `offset`: transition to
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
  void record_download(VkCommandBuffer cb, const Download& d, VkBuffer buffer);
  // The depth aspect of an application's depth rect (DEPTH_STENCIL_ATTACHMENT_OPTIMAL).
  static Download depth_download(const AppDepth& d, VkDeviceSize offset);
  void record_host_read_barrier(VkCommandBuffer cb);
  // `buffer` at `offset` (width x height 4-byte texels) into the whole image, its old contents
  // discarded; the image ends in COLOR_ATTACHMENT_OPTIMAL.
  void record_upload(VkCommandBuffer cb, VkBuffer buffer, VkDeviceSize offset, VkImage image, int width, int height);

  VkDevice device_ = VK_NULL_HANDLE;
  PFN_vkGetDeviceProcAddr get_device_proc_ = nullptr;
  VkQueue queue_handle_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  bool family_has_compute_ = false;
  std::unique_ptr<xrcommon::ForeignQueue> queue_;  // the session queue, bounded waits
  Buffer download_, upload_;
  VkPhysicalDeviceMemoryProperties memory_{};
  std::int64_t host_readbacks_ = 0;
  // The composition pass's objects (gpu_composite.cpp).
  struct Gpu {
    VkShaderModule shader = VK_NULL_HANDLE;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE, border_pipeline = VK_NULL_HANDLE;  // the composite and border passes
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
    Buffer params, staging;                 // host-visible
    Buffer traced, app, app_depth, out, background;  // device-local
    std::int64_t uploaded = -1;                       // the traced frame in `traced`
    bool uploaded_depth = false;                      // with its depths
  };
  std::unique_ptr<Gpu> gpu_;
  std::unique_ptr<xrcommon::ForeignQueue> pass_;  // the composition pass's submissions
  // pass_ between xrEndFrame's composition and finish() from xrDestroySwapchain, which an
  // application may call on another thread.
  std::mutex pass_mutex_;
  void destroy_gpu();

#define FOVEA_APP_VK(X)                                                                                          \
  X(vkGetDeviceQueue) X(vkCmdPipelineBarrier) X(vkCmdCopyImageToBuffer) X(vkCmdCopyBufferToImage)             \
  X(vkCreateBuffer) X(vkDestroyBuffer) X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory)     \
  X(vkBindBufferMemory) X(vkMapMemory) X(vkUnmapMemory) X(vkCmdCopyBuffer) X(vkCreateShaderModule)             \
  X(vkDestroyShaderModule) X(vkCreateDescriptorSetLayout) X(vkDestroyDescriptorSetLayout)                       \
  X(vkCreatePipelineLayout) X(vkDestroyPipelineLayout) X(vkCreateComputePipelines) X(vkDestroyPipeline)         \
  X(vkCreateDescriptorPool) X(vkDestroyDescriptorPool) X(vkAllocateDescriptorSets) X(vkUpdateDescriptorSets)    \
  X(vkCmdBindPipeline) X(vkCmdBindDescriptorSets) X(vkCmdPushConstants) X(vkCmdDispatch)
#define FOVEA_APP_VK_MEMBER(name) PFN_##name name##_ = nullptr;
  FOVEA_APP_VK(FOVEA_APP_VK_MEMBER)
#undef FOVEA_APP_VK_MEMBER
};

}  // namespace fovea::layer
