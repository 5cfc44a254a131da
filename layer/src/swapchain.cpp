// Swapchain intercepts: forwarded (creation with the transfer-source usage added); the layer records each swapchain's images
// (enumerated by the layer itself at creation: an application need not enumerate them to
// submit them) and which one was released last (what the application submits in xrEndFrame).
// An acquired image is returned once no composition pass reads it any more; destruction first
// waits for the passes naming the swapchain's images.
#include <vector>

#include "layer.hpp"
#include "log.hpp"

namespace fovea::layer {
namespace {

const Dispatch* next_for_swapchain(XrSwapchain sc) {
  auto it = layer().swapchains.find(sc);
  return next_for_session(it == layer().swapchains.end() ? XrSession(XR_NULL_HANDLE) : it->second.session);
}

// The renderer of the swapchain's session, if it has one (under Layer::mutex).
std::shared_ptr<FrameRenderer> renderer_for_swapchain(XrSwapchain sc) {
  const auto it = layer().swapchains.find(sc);
  if (it == layer().swapchains.end()) return nullptr;
  const auto s = layer().sessions.find(it->second.session);
  return s == layer().sessions.end() ? nullptr : s->second.renderer;
}

// A composition pass may still read the application's images on the device after xrEndFrame
// returned: an image is given back to the application (acquired) or destroyed only after the
// passes that read it. Outside Layer::mutex.
template <typename Wait>
void finish_composition(FrameRenderer* renderer, const char* call, Wait wait) {
  if (!renderer) return;
  try {
    wait(*renderer);
  } catch (const std::exception& e) {
    FOVEA_LAYER_ERROR("%s: a composition pass did not finish: %s", call, e.what());
  }
}

// The images of swapchain `sc` (under Layer::mutex).
std::vector<VkImage> swapchain_images(XrSwapchain sc) {
  const auto it = layer().swapchains.find(sc);
  return it == layer().swapchains.end() ? std::vector<VkImage>{} : it->second.images;
}

}  // namespace

XrResult intercept::xrCreateSwapchain(XrSession session, const XrSwapchainCreateInfo* info, XrSwapchain* swapchain) {
  PFN_xrCreateSwapchain next = nullptr;
  PFN_xrEnumerateSwapchainImages enumerate = nullptr;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_session(session);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrCreateSwapchain;
    enumerate = d->xrEnumerateSwapchainImages;
  }
  // The layer copies the application's released images back (colour, and depth for depth
  // compositing), so it asks for the transfer usage that needs; anything else unchanged, and
  // a malformed create info goes down as it is, for the runtime to report.
  XrSwapchainCreateInfo readable{};
  if (info && info->type == XR_TYPE_SWAPCHAIN_CREATE_INFO) {
    readable = *info;
    readable.usageFlags |= XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT;
  }
  const XrResult r = next(session, readable.type == XR_TYPE_SWAPCHAIN_CREATE_INFO ? &readable : info, swapchain);
  if (XR_SUCCEEDED(r)) {
    // Without the images (an enumeration failure) the swapchain is never composited.
    std::vector<VkImage> images;
    uint32_t n = 0;
    if (XR_SUCCEEDED(enumerate(*swapchain, 0, &n, nullptr))) {
      std::vector<XrSwapchainImageVulkanKHR> vk(n, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR});
      if (XR_SUCCEEDED(enumerate(*swapchain, n, &n, reinterpret_cast<XrSwapchainImageBaseHeader*>(vk.data()))))
        for (const auto& i : vk) images.push_back(i.image);
    }
    std::lock_guard lock(layer().mutex);
    SwapchainState& s = layer().swapchains[*swapchain];
    s.session = session;
    s.info = *info;
    s.info.next = nullptr;
    s.images = std::move(images);
  }
  return r;
}

XrResult intercept::xrDestroySwapchain(XrSwapchain swapchain) {
  PFN_xrDestroySwapchain next = nullptr;
  std::shared_ptr<FrameRenderer> renderer;
  std::vector<VkImage> images;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_swapchain(swapchain);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrDestroySwapchain;
    renderer = renderer_for_swapchain(swapchain);
    images = swapchain_images(swapchain);
  }
  finish_composition(renderer.get(), __func__, [&](FrameRenderer& r) { r.forget_images(images); });
  const XrResult r = next(swapchain);
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(layer().mutex);
    layer().swapchains.erase(swapchain);
  }
  return r;
}

XrResult intercept::xrAcquireSwapchainImage(XrSwapchain swapchain, const XrSwapchainImageAcquireInfo* info,
                                            uint32_t* index) {
  PFN_xrAcquireSwapchainImage next = nullptr;
  std::shared_ptr<FrameRenderer> renderer;
  {
    std::lock_guard lock(layer().mutex);
    const Dispatch* d = next_for_swapchain(swapchain);
    if (!d) return XR_ERROR_HANDLE_INVALID;
    next = d->xrAcquireSwapchainImage;
    renderer = renderer_for_swapchain(swapchain);
  }
  const XrResult r = next(swapchain, info, index);
  if (XR_SUCCEEDED(r)) {
    VkImage image = VK_NULL_HANDLE;
    {
      std::lock_guard lock(layer().mutex);
      auto it = layer().swapchains.find(swapchain);
      if (it != layer().swapchains.end()) {
        it->second.acquired.push_back(*index);
        if (*index < it->second.images.size()) image = it->second.images[*index];
      }
    }
    // Only the passes that read this image: the application may render into it once acquired.
    if (image != VK_NULL_HANDLE)
      finish_composition(renderer.get(), __func__, [&](FrameRenderer& fr) { fr.finish_composition(image); });
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
