#pragma once
// Vulkan failures. Bad input (a device override matching nothing, an unknown shader, a
// zero-sized buffer) is core::InputError; a failing Vulkan call is VulkanError.
#include <stdexcept>
#include <string>

#include <vulkan/vulkan_core.h>

namespace fovea::gpu {

class VulkanError : public std::runtime_error {
 public:
  VulkanError(VkResult result, const std::string& what);
  VkResult result() const { return result_; }

 private:
  VkResult result_;
};

// "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc.
const char* result_name(VkResult result);

// Throws VulkanError naming `call` unless result is VK_SUCCESS.
inline void check(VkResult result, const char* call) {
  if (result != VK_SUCCESS) throw VulkanError(result, call);
}

// For a call that creates or allocates `bytes` for `what` (a buffer or image), with
// `heap_bytes` the heap it allocates from (either 0: not known yet). A request larger than the heap,
// or an out-of-memory result, is a size the input asked for (a display's raster, a scene)
// that this device cannot hold: core::InputError naming `what`, its size and the heap.
// Other failures throw VulkanError as check() does.
void check_fits(VkResult result, const char* call, const std::string& what, VkDeviceSize bytes,
                VkDeviceSize heap_bytes);

}  // namespace fovea::gpu
