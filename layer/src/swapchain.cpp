// Swapchain intercepts: forwarded unchanged; the layer records each swapchain's images and
// which one was released last (what the application submits in xrEndFrame).
#include <algorithm>

#include "layer.hpp"
#include "log.hpp"

namespace fovea::layer {
namespace {

const Dispatch* next_for_swapchain(XrSwapchain sc) {
  auto it = layer().swapchains.find(sc);
  return next_for_session(it == layer().swapchains.end() ? XrSession(XR_NULL_HANDLE) : it->second.session);
}

}  // namespace

XrResult intercept::xrCreateSwapchain(XrSession session, const XrSwapchainCreateInfo* info, XrSwapchain* swapchain) {
  PFN_xrCreateSwapchain next = nullptr;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_session(session);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrCreateSwapchain;
  }
  const XrResult r = next(session, info, swapchain);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(layer().mutex);
    SwapchainState& s = layer().swapchains[*swapchain];
    s.session = session;
    s.info = *info;
    s.info.next = nullptr;
  }
  return r;
}

XrResult intercept::xrDestroySwapchain(XrSwapchain swapchain) {
  PFN_xrDestroySwapchain next = nullptr;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_swapchain(swapchain);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrDestroySwapchain;
  }
  const XrResult r = next(swapchain);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(layer().mutex);
    layer().swapchains.erase(swapchain);
  }
  return r;
}

XrResult intercept::xrEnumerateSwapchainImages(XrSwapchain swapchain, uint32_t capacity, uint32_t* count,
                                               XrSwapchainImageBaseHeader* images) {
  PFN_xrEnumerateSwapchainImages next = nullptr;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_swapchain(swapchain);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrEnumerateSwapchainImages;
  }
  const XrResult r = next(swapchain, capacity, count, images);
  if (XR_SUCCEEDED(r) && capacity && images && images->type == XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR) {
    std::lock_guard lock(layer().mutex);
    auto it = layer().swapchains.find(swapchain);
    if (it != layer().swapchains.end()) {
      const auto* vk = reinterpret_cast<const XrSwapchainImageVulkanKHR*>(images);
      it->second.images.assign(*count, VK_NULL_HANDLE);
      std::transform(vk, vk + *count, it->second.images.begin(), [](const auto& i) { return i.image; });
    }
  }
  return r;
}

XrResult intercept::xrAcquireSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageAcquireInfo* info,
                                            uint32_t* index) {
  PFN_xrAcquireSwapchainImage next = nullptr;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_swapchain(swapchain);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrAcquireSwapchainImage;
  }
  const XrResult r = next(swapchain, info, index);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(layer().mutex);
    auto it = layer().swapchains.find(swapchain);
    if (it != layer().swapchains.end()) it->second.acquired.push_back(*index);
  }
  return r;
}

XrResult intercept::xrReleaseSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageReleaseInfo* info) {
  PFN_xrReleaseSwapchainImage next = nullptr;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_swapchain(swapchain);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrReleaseSwapchainImage;
  }
  const XrResult r = next(swapchain, info);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(layer().mutex);
    auto it = layer().swapchains.find(swapchain);
    if (it != layer().swapchains.end() && !it->second.acquired.empty()) {
      it->second.last_released = it->second.acquired.front();
      it->second.acquired.erase(it->second.acquired.begin());
    }
  }
  return r;
}

}  // namespace fovea::layer
