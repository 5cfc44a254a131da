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
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>

#include "composite.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/gpu/foreign_queue.hpp"
#include "frame_renderer.hpp"
#include "traced_slots.hpp"

namespace fovea::layer {

// Throws std::runtime_error naming the call unless r is VK_SUCCESS.
void app_check(VkResult r, const char* what);

// D16_UNORM, X8_D24_UNORM_PACK32, D24_UNORM_S8_UINT, D32_SFLOAT, D32_SFLOAT_S8_UINT.
bool depth_format_supported(VkFormat f);

// What a pre-recorded GPU composition pass (AppDevice::composite_gpu) was recorded for: a frame
// whose images, rects and steps match submits it again.
struct CompositionPassKey {
  std::array<VkImage, 2> app{}, target{}, depth{};
  std::array<std::array<std::int32_t, 4>, 2> app_rect{}, depth_rect{};  // x, y, width, height
  std::array<std::uint32_t, 2> app_layer{}, depth_layer{};
  std::array<VkFormat, 2> depth_format{};
  std::array<std::int32_t, 2> out_w{}, out_h{};
  bool with_app = false, by_depth = false, border = false;
  bool operator==(const CompositionPassKey&) const = default;
  bool names(VkImage image) const;
};

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
  // compute pass on the session queue and `slots` slots for path-traced frames of
  // `traced_width` x `traced_height` per eye in host-visible memory of this device; throws
  // std::runtime_error with the reason when the device cannot run it (the session queue's
  // family has no compute, no memory type).
  // With VK_KHR_external_memory_fd on the device (VulkanBinding::external_memory_fd()) the slots
  // are exportable device memory instead (shared_slots(); slot_colour and slot_depth then
  // throw), unless the export fails: shared_slots() is empty then, and no_shared_slots() says why.
  void enable_gpu_composition(int traced_width, int traced_height, int slots = 3);
  bool gpu_composition() const { return gpu_ != nullptr; }
  // The slots' memory as a new opaque file descriptor for the layer's device to import, with
  // the device's VkPhysicalDeviceIDProperties::deviceUUID (the layer's device must be on the
  // same physical device); empty on the host-written path.
  struct SharedSlots {
    gpu::ExternalMemory memory;
    std::array<std::uint8_t, VK_UUID_SIZE> device_uuid{};
  };
  std::optional<SharedSlots> shared_slots() const;
  const std::string& no_shared_slots() const { return no_shared_; }
  // The traced-frame slots (null before enable_gpu_composition). A thread that claimed slot `s`
  // writes its frame at slot_colour(s, eye) (4-byte pixels in the swapchain's encoding,
  // row-major) and slot_depth(s, eye) (FramePipeline::depth's view distances): persistently
  // mapped, so the render thread writes them without a call on this device.
  std::shared_ptr<SlotPool> traced_slots() const;
  std::uint8_t* slot_colour(int slot, int eye) const;
  float* slot_depth(int slot, int eye) const;
  struct GpuEye {
    // The views and the rotation; the traced pixels come from the slot, `traced`, `app` and
    // `app_depth` are unused (the images below are read on the device).
    EyeComposition composition;
    Read app;                      // the application's projection view (unused in scene-only mode)
    std::optional<AppDepth> depth;  // its depth: compositing by depth (both eyes), with the slot's depths
    VkImage target;                // written whole (out_view's raster), ends in COLOR_ATTACHMENT_OPTIMAL
  };
  // One submission on the session queue, not waited for: copies the application's rects
  // (and depth rects) into device buffers, runs the composition pass on the traced frame in
  // `slot` and copies the results into the targets. The command buffer is recorded once per
  // combination of images and rects (and kept; a second copy is recorded while the first is
  // still in flight, up to kPasses in all); a frame writes its parameters into that command
  // buffer's own block of a persistently mapped buffer and submits it, waiting only when every
  // pass is in flight. Later work on the queue (the application's
  // next rendering into its images, the runtime's reads) comes after it. Slots retired since
  // the last call are released once no pending pass reads them.
  void composite_gpu(int slot, const std::array<GpuEye, 2>& eyes, const CompositionRule& rule);
  // Waits for the pending passes that read or write `image` (before the application gets it
  // back: an acquisition); returns how many submitted passes named it and had not been seen
  // finished (polled; waited for only while still in flight). Others keep running.
  int finish_image(VkImage image);
  // Waits for the passes naming any of `images` and forgets their command buffers (before the
  // images are destroyed: a recorded command buffer must not outlive them).
  void forget_images(const std::vector<VkImage>& images);
  // Waits for every composition pass still running.
  void finish();
  // Gives the slots whose frames are gone back to the render thread, waiting for the passes
  // that read them (composite_gpu does so without waiting): before waiting for the render
  // thread, which may need a slot.
  void release_retired_slots();
  // The GPU path's work on the application's thread so far: command buffers recorded,
  // descriptor set updates, submissions, and host waits for a pass still in flight (its
  // fence polled unsignalled first): by composite_gpu for a pass it must reuse, by
  // finish_image for the acquired image. Recording and descriptor updates happen at the first
  // frames and when images or buffer sizes change, not per frame.
  struct GpuStats {
    std::int64_t recordings = 0, descriptor_updates = 0, submissions = 0, reuse_waits = 0, acquire_waits = 0;
    double submit_ms = 0;  // the last composite_gpu's vkQueueSubmit (lavapipe does work in it)
    std::int64_t submit_preemptions = 0;  // the calling thread's involuntary context switches during it
  };
  GpuStats gpu_stats() const;

 private:
  struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;  // host-visible buffers only
    VkDeviceSize size = 0;
    bool exported = false;  // dedicated memory exportable as an opaque file descriptor
    std::uint32_t memory_type = 0;
    VkDeviceSize allocation = 0;
  };
  // At least `size` bytes: host-visible and coherent (mapped), or device-local when `host` is
  // false; `prefer_device_local` picks host-visible memory that is device-local too when the
  // device has it (what a shader reads every frame).
  // `exported`: dedicated memory, device-local where the device has it, that another device
  // of this physical device can import (an opaque file descriptor); throws with the reason
  // when the device cannot.
  void reserve(Buffer& b, VkDeviceSize size, VkBufferUsageFlags usage, bool host = true,
               bool prefer_device_local = false, bool exported = false);
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
  std::unique_ptr<gpu::ForeignQueue> queue_;  // the session queue, bounded waits
  Buffer download_, upload_;
  VkPhysicalDeviceMemoryProperties memory_{};
  VkDeviceSize storage_alignment_ = 256;  // minStorageBufferOffsetAlignment
  // The shared path (VulkanBinding::external_memory_fd()): the device's UUID and its export.
  bool external_memory_ = false;
  std::string no_shared_;
  std::array<std::uint8_t, VK_UUID_SIZE> device_uuid_{};
  PFN_vkGetMemoryFdKHR get_memory_fd_ = nullptr;
  PFN_vkGetPhysicalDeviceExternalBufferProperties external_buffer_properties_ = nullptr;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  std::int64_t host_readbacks_ = 0;
  // The composition pass's objects (gpu_composite.cpp).
  using PassKey = CompositionPassKey;
  // A pre-recorded composition pass: its command buffer, fence and parameter block (the
  // block of the same index in Gpu::params).
  struct Pass {
    PassKey key;
    bool recorded = false;
    bool pending = false;    // submitted, its fence not yet seen signalled
    int slot = -1;           // the traced slot its last submission reads
    std::uint64_t used = 0;  // when it was last submitted (Gpu::clock), for eviction
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
  };
  static constexpr std::size_t kPasses = 8;
  struct Gpu {
    gpu::ForeignPipelines program;  // the border and composite passes' pipelines, their layouts
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VkCommandPool commands = VK_NULL_HANDLE;
    bool set_written = false;  // the set names the current buffers
    Buffer params;             // host-visible: one parameter block per pass, `params_stride` apart
    VkDeviceSize params_stride = 0;
    Buffer traced;             // host-visible: the traced-frame slots, written by the render thread
    Buffer app, app_depth, out, background;  // device-local
    int traced_w = 0, traced_h = 0;
    std::shared_ptr<SlotPool> slots;
    std::uint32_t retiring = 0;  // retired slots still read by a pending pass
    std::array<Pass, kPasses> passes;
    std::uint64_t clock = 0;
    std::optional<bool> decode_srgb;  // what `decode` holds
    std::array<float, 256> decode{};
    GpuStats counters;
  };
  std::unique_ptr<Gpu> gpu_;
  // gpu_'s passes between xrEndFrame's composition and the waits of xrAcquireSwapchainImage
  // and xrDestroySwapchain, which an application may call on another thread.
  mutable std::mutex pass_mutex_;
  void destroy_gpu();
  // Waits for a pass's fence (bounded) if it is still in flight, counting the wait in `waits`.
  void wait_pass(Pass& p, std::int64_t& waits);
  bool pass_pending(Pass& p);  // polls without waiting
  void record_pass(Pass& p, std::size_t index);
  void reserve_gpu_buffers(VkDeviceSize app_bytes, VkDeviceSize depth_bytes);
  // Slots retired since the last call, or still read then, released when no pending pass
  // reads them (after waiting for those passes with `wait`). Under pass_mutex_.
  void release_retired(bool wait);

#define FOVEA_APP_VK(X)                                                                                          \
  X(vkGetDeviceQueue) X(vkCmdPipelineBarrier) X(vkCmdCopyImageToBuffer) X(vkCmdCopyBufferToImage)                \
  X(vkCreateBuffer) X(vkDestroyBuffer) X(vkGetBufferMemoryRequirements) X(vkAllocateMemory) X(vkFreeMemory)      \
  X(vkBindBufferMemory) X(vkMapMemory) X(vkUnmapMemory) X(vkCreateDescriptorPool)                                \
  X(vkDestroyDescriptorPool) X(vkAllocateDescriptorSets) X(vkUpdateDescriptorSets)                               \
  X(vkCmdBindPipeline) X(vkCmdBindDescriptorSets) X(vkCmdPushConstants) X(vkCmdDispatch)                         \
  X(vkCreateCommandPool) X(vkDestroyCommandPool) X(vkAllocateCommandBuffers) X(vkBeginCommandBuffer)             \
  X(vkEndCommandBuffer) X(vkQueueSubmit) X(vkCreateFence) X(vkDestroyFence) X(vkWaitForFences) X(vkResetFences)  \
  X(vkGetFenceStatus)
#define FOVEA_APP_VK_MEMBER(name) PFN_##name name##_ = nullptr;
  FOVEA_APP_VK(FOVEA_APP_VK_MEMBER)
#undef FOVEA_APP_VK_MEMBER
};

}  // namespace fovea::layer
