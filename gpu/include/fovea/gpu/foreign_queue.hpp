#pragma once
// One-shot command submission on a Vulkan device the caller does not own: the application's
// VkDevice, which the runtime and the API layer may use only inside the OpenXR calls that let
// them (the session queue during swapchain and frame calls). Its functions come from the
// device's own vkGetDeviceProcAddr, so a caller needs no device-level dispatch of its own.
#include <cstdint>
#include <functional>
#include <string>

#include <vulkan/vulkan.h>

namespace fovea::gpu {

class ForeignQueue {
 public:
  static constexpr std::uint64_t kNoTimeout = UINT64_MAX;
  // `device_name` names the device in error messages ("the application's device");
  // `timeout_ns` bounds each wait (kNoTimeout: unbounded). Throws std::runtime_error.
  ForeignQueue(VkDevice device, PFN_vkGetDeviceProcAddr get_device_proc, std::uint32_t family, VkQueue queue,
               std::uint64_t timeout_ns, std::string device_name);
  ~ForeignQueue();  // waits (bounded) for a submission still running
  ForeignQueue(const ForeignQueue&) = delete;
  ForeignQueue& operator=(const ForeignQueue&) = delete;

  // Records with `record` into the one command buffer, submits it and waits for completion.
  // Throws std::runtime_error naming the call and the device on a Vulkan failure or a wait
  // beyond the timeout (a hung device fails the caller instead of hanging it); an exception
  // from `record` propagates, and the next run() starts afresh either way.
  void run(const std::function<void(VkCommandBuffer)>& record);
  // The same without the wait: returns once submitted. The next submit(), run() or wait()
  // first waits for it (the one command buffer is reused).
  void submit(const std::function<void(VkCommandBuffer)>& record);
  // Waits for the last submission, if one is still pending; throws as run().
  void wait();

 private:
  void check(VkResult r, const char* what) const;
  void destroy();

  VkDevice device_;
  VkQueue queue_;
  std::uint64_t timeout_ns_;
  std::string device_name_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool pending_ = false;  // submitted, not yet waited for

#define FOVEA_FOREIGN_VK(X)                                                                                  \
  X(vkCreateCommandPool) X(vkDestroyCommandPool) X(vkAllocateCommandBuffers) X(vkResetCommandBuffer)         \
  X(vkBeginCommandBuffer) X(vkEndCommandBuffer) X(vkQueueSubmit) X(vkCreateFence) X(vkDestroyFence)          \
  X(vkWaitForFences) X(vkResetFences)
#define FOVEA_FOREIGN_VK_MEMBER(name) PFN_##name name##_ = nullptr;
  FOVEA_FOREIGN_VK(FOVEA_FOREIGN_VK_MEMBER)
#undef FOVEA_FOREIGN_VK_MEMBER
};

}  // namespace fovea::gpu
