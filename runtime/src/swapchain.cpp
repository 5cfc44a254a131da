// Swapchains backed by VkImages on the application's device, with the acquire -> wait ->
// release discipline of the core specification.
#include <cmath>

#include <algorithm>

#include "api.hpp"
#include "state.hpp"
#include "vk_util.hpp"

namespace fovea::runtime {
namespace {

// Offered formats, preferred first (sRGB colour as the specification recommends, then depth
// for XR_KHR_composition_layer_depth).
const std::vector<int64_t> kFormats = {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_UNORM,
                                       VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_D32_SFLOAT,     VK_FORMAT_D16_UNORM};
constexpr uint32_t kImageCount = 3;

bool depth_format(int64_t f) { return f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D16_UNORM; }

// The application's usage (XR_KHR_vulkan_enable's table), plus sampling: the compositor
// samples the images, as compositors do (the extension lets a runtime create images with at
// least the requested usage; it also keeps an image with usage 0 creatable). Nothing else is
// added, so an application or API layer that copies from its images must ask for
// XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT, as on other runtimes.
VkImageUsageFlags vk_usage(XrSwapchainUsageFlags u) {
  VkImageUsageFlags v = VK_IMAGE_USAGE_SAMPLED_BIT;
  if (u & XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT) v |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  if (u & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) v |= VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (u & XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT) v |= VK_IMAGE_USAGE_STORAGE_BIT;
  if (u & XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT) v |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  if (u & XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT) v |= VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  if (u & XR_SWAPCHAIN_USAGE_SAMPLED_BIT) v |= VK_IMAGE_USAGE_SAMPLED_BIT;
  if (u & XR_SWAPCHAIN_USAGE_INPUT_ATTACHMENT_BIT_MND) v |= VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT;
  return v;
}

constexpr XrSwapchainUsageFlags kKnownUsage =
    XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
    XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT |
    XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT | XR_SWAPCHAIN_USAGE_SAMPLED_BIT | XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT |
    XR_SWAPCHAIN_USAGE_INPUT_ATTACHMENT_BIT_MND;

}  // namespace

Swapchain::~Swapchain() {
  if (!session) return;
  for (VkImage i : images) vkDestroyImage(session->vk_device, i, nullptr);
  for (VkDeviceMemory m : memory) vkFreeMemory(session->vk_device, m, nullptr);
}

XrResult api::xrEnumerateSwapchainFormats(XrSession session, uint32_t capacity, uint32_t* count, int64_t* formats) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Session>(session)) return XR_ERROR_HANDLE_INVALID;
    return two_call(capacity, count, formats, kFormats);
  });
}

XrResult api::xrCreateSwapchain(XrSession session, const XrSwapchainCreateInfo* info, XrSwapchain* swapchain) {
  return guarded(__func__, [&]() -> XrResult {
    Session* s = find<Session>(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_SWAPCHAIN_CREATE_INFO) || !swapchain) return XR_ERROR_VALIDATION_FAILURE;
    if (info->createFlags & ~XrSwapchainCreateFlags(XR_SWAPCHAIN_CREATE_PROTECTED_CONTENT_BIT |
                                                    XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT))
      return XR_ERROR_VALIDATION_FAILURE;
    if (info->createFlags & XR_SWAPCHAIN_CREATE_PROTECTED_CONTENT_BIT) return XR_ERROR_FEATURE_UNSUPPORTED;
    if (info->usageFlags & ~kKnownUsage) return XR_ERROR_VALIDATION_FAILURE;
    if (std::find(kFormats.begin(), kFormats.end(), info->format) == kFormats.end())
      return XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED;
    const bool depth = depth_format(info->format);
    if ((depth && (info->usageFlags & (XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT))) ||
        (!depth && (info->usageFlags & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT)))
      return XR_ERROR_FEATURE_UNSUPPORTED;
    if (info->width == 0 || info->height == 0 || info->width > kMaxSwapchainSize ||
        info->height > kMaxSwapchainSize || info->arraySize == 0 || info->arraySize > 16)
      return XR_ERROR_VALIDATION_FAILURE;
    if (info->sampleCount != 1 || info->faceCount != 1) return XR_ERROR_FEATURE_UNSUPPORTED;
    const uint32_t max_mips = 1 + uint32_t(std::floor(std::log2(double(std::max(info->width, info->height)))));
    if (info->mipCount == 0 || info->mipCount > max_mips) return XR_ERROR_VALIDATION_FAILURE;

    auto sc = std::make_unique<Swapchain>();
    sc->session = s;
    sc->info = *info;
    sc->info.next = nullptr;
    const uint32_t n = (info->createFlags & XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT) ? 1 : kImageCount;
    for (uint32_t i = 0; i < n; ++i) {
      VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
      ci.flags = (info->usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT) ? VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT : 0;
      ci.imageType = VK_IMAGE_TYPE_2D;
      ci.format = VkFormat(info->format);
      ci.extent = {info->width, info->height, 1};
      ci.mipLevels = info->mipCount;
      ci.arrayLayers = info->arraySize;
      ci.samples = VK_SAMPLE_COUNT_1_BIT;
      ci.tiling = VK_IMAGE_TILING_OPTIMAL;
      ci.usage = vk_usage(info->usageFlags);
      ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
      ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
      VkImage image = VK_NULL_HANDLE;
      if (vkCreateImage(s->vk_device, &ci, nullptr, &image) != VK_SUCCESS) return XR_ERROR_RUNTIME_FAILURE;
      sc->images.push_back(image);  // owned from here on (freed by ~Swapchain)
      VkMemoryRequirements req;
      vkGetImageMemoryRequirements(s->vk_device, image, &req);
      VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
      ai.allocationSize = req.size;
      ai.memoryTypeIndex = find_memory_type(s->vk_physical, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
      VkDeviceMemory mem = VK_NULL_HANDLE;
      if (vkAllocateMemory(s->vk_device, &ai, nullptr, &mem) != VK_SUCCESS) return XR_ERROR_OUT_OF_MEMORY;
      sc->memory.push_back(mem);
      if (vkBindImageMemory(s->vk_device, image, mem, 0) != VK_SUCCESS) return XR_ERROR_RUNTIME_FAILURE;
    }
    sc->layout_ready.assign(n, false);
    FOVEA_LOG_INFO("swapchain %ux%u format %lld usage 0x%llx, %u images", info->width, info->height,
                   static_cast<long long>(info->format), static_cast<unsigned long long>(info->usageFlags), n);
    *swapchain = to_handle<XrSwapchain>(add_object(std::move(sc), s->id));
    return XR_SUCCESS;
  });
}

XrResult api::xrDestroySwapchain(XrSwapchain swapchain) {
  return guarded(__func__, [&]() -> XrResult {
    Swapchain* sc = find<Swapchain>(swapchain);
    if (!sc) return XR_ERROR_HANDLE_INVALID;
    destroy_object(sc->id);
    return XR_SUCCESS;
  });
}

XrResult api::xrEnumerateSwapchainImages(XrSwapchain swapchain, uint32_t capacity, uint32_t* count,
                                         XrSwapchainImageBaseHeader* images) {
  return guarded(__func__, [&]() -> XrResult {
    Swapchain* sc = find<Swapchain>(swapchain);
    if (!sc) return XR_ERROR_HANDLE_INVALID;
    if (!count || (capacity && !images)) return XR_ERROR_VALIDATION_FAILURE;
    const uint32_t n = uint32_t(sc->images.size());
    *count = n;
    if (capacity == 0) return XR_SUCCESS;
    if (capacity < n) return XR_ERROR_SIZE_INSUFFICIENT;
    auto* out = reinterpret_cast<XrSwapchainImageVulkanKHR*>(images);
    for (uint32_t i = 0; i < n; ++i)
      if (out[i].type != XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR) return XR_ERROR_VALIDATION_FAILURE;
    for (uint32_t i = 0; i < n; ++i) out[i].image = sc->images[i];
    return XR_SUCCESS;
  });
}

XrResult api::xrAcquireSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageAcquireInfo* info,
                                      uint32_t* index) {
  return guarded(__func__, [&]() -> XrResult {
    Swapchain* sc = find<Swapchain>(swapchain);
    if (!sc) return XR_ERROR_HANDLE_INVALID;
    if ((info && info->type != XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO) || !index) return XR_ERROR_VALIDATION_FAILURE;
    if (sc->acquired.size() >= sc->images.size()) return XR_ERROR_CALL_ORDER_INVALID;
    if ((sc->info.createFlags & XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT) && sc->ever_acquired)
      return XR_ERROR_CALL_ORDER_INVALID;
    const uint32_t i = sc->next_image;
    // The application expects COLOR_ATTACHMENT_OPTIMAL (depth: DEPTH_STENCIL_ATTACHMENT_OPTIMAL)
    // on the session's queue (XR_KHR_vulkan_enable, swapchain image layout); new images are
    // UNDEFINED, so the first acquisition transitions them.
    if (!sc->layout_ready[i]) {
      const bool depth = sc->is_depth();
      sc->session->gpu->run([&](VkCommandBuffer cmd) {
        transition(cmd, sc->images[i], depth, VK_IMAGE_LAYOUT_UNDEFINED,
                   depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                   0,
                   depth ? VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT : VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                   VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                   depth ? VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT : VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT);
      });
      sc->layout_ready[i] = true;
    }
    sc->next_image = (i + 1) % uint32_t(sc->images.size());
    sc->acquired.push_back(i);
    sc->ever_acquired = true;
    *index = i;
    return XR_SUCCESS;
  });
}

XrResult api::xrWaitSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageWaitInfo* info) {
  return guarded(__func__, [&]() -> XrResult {
    Swapchain* sc = find<Swapchain>(swapchain);
    if (!sc) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO)) return XR_ERROR_VALIDATION_FAILURE;
    // One image at a time: a waited image must be released before the next wait (core spec,
    // xrWaitSwapchainImage), and only an acquired image can be waited on.
    if (sc->waited || sc->acquired.empty()) return XR_ERROR_CALL_ORDER_INVALID;
    // The compositor finishes with an image inside xrEndFrame, so an acquired image is
    // always ready: no timeout can occur.
    sc->waited = true;
    return XR_SUCCESS;
  });
}

XrResult api::xrReleaseSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageReleaseInfo* info) {
  return guarded(__func__, [&]() -> XrResult {
    Swapchain* sc = find<Swapchain>(swapchain);
    if (!sc) return XR_ERROR_HANDLE_INVALID;
    if (info && info->type != XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO) return XR_ERROR_VALIDATION_FAILURE;
    if (!sc->waited) return XR_ERROR_CALL_ORDER_INVALID;
    sc->last_released = sc->acquired.front();
    sc->acquired.pop_front();
    sc->waited = false;
    return XR_SUCCESS;
  });
}

}  // namespace fovea::runtime
