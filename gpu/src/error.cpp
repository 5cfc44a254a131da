#include "fovea/gpu/error.hpp"

#include "fovea/core/error.hpp"

namespace fovea::gpu {

namespace {
std::string mib(VkDeviceSize bytes) { return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB"; }
}  // namespace

void check_fits(VkResult result, const char* call, const std::string& what, VkDeviceSize bytes,
                VkDeviceSize heap_bytes) {
  const std::string heap = heap_bytes ? "the device's memory heap holds " + mib(heap_bytes) : "";
  const std::string hint = "; a smaller display raster, budget or scene fits";
  if (heap_bytes && bytes > heap_bytes)
    throw core::InputError(what + ": " + mib(bytes) + ", more than " + heap + hint);
  if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY)
    throw core::InputError(what + (bytes ? ": " + mib(bytes) : "") + ": " + call + " ran out of memory (" +
                           result_name(result) +
                           (heap.empty() ? "" : "; " + heap) + ")" + hint);
  check(result, call);
}

VulkanError::VulkanError(VkResult result, const std::string& what)
    : std::runtime_error(what + " failed: " + result_name(result)), result_(result) {}

const char* result_name(VkResult result) {
  switch (result) {
#define FOVEA_CASE(r) \
  case r:             \
    return #r;
    FOVEA_CASE(VK_SUCCESS)
    FOVEA_CASE(VK_NOT_READY)
    FOVEA_CASE(VK_TIMEOUT)
    FOVEA_CASE(VK_INCOMPLETE)
    FOVEA_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    FOVEA_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    FOVEA_CASE(VK_ERROR_INITIALIZATION_FAILED)
    FOVEA_CASE(VK_ERROR_DEVICE_LOST)
    FOVEA_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    FOVEA_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    FOVEA_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    FOVEA_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    FOVEA_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    FOVEA_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    FOVEA_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    FOVEA_CASE(VK_ERROR_FRAGMENTED_POOL)
    FOVEA_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    FOVEA_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    FOVEA_CASE(VK_ERROR_FRAGMENTATION)
    FOVEA_CASE(VK_ERROR_VALIDATION_FAILED_EXT)
#undef FOVEA_CASE
    default:
      return "VK_ERROR_UNKNOWN";
  }
}

}  // namespace fovea::gpu
