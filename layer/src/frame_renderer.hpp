#pragma once
// The hook for the path-tracing part of the layer. A FrameRenderer would render the
// configured scene foveated (renderer/, reconstruction/) for the views the runtime located,
// on the application's Vulkan device, into layer-owned swapchains, and return the projection
// layer that replaces the application's. It needs the renderer and the reconstruction
// modules; until they are integrated make_frame_renderer returns null and the layer passes
// frames through, measuring only.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

namespace fovea::layer {

// The application's Vulkan objects, from XrGraphicsBindingVulkan(2)KHR at xrCreateSession.
struct VulkanBinding {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0, queue_index = 0;
  bool valid() const { return device != VK_NULL_HANDLE; }
};

// One projection view the application submitted: its last released swapchain image
// (COLOR_ATTACHMENT_OPTIMAL, owned by the session queue), for compositing over it.
struct AppView {
  VkImage image = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  XrRect2Di rect{};
  std::uint32_t array_index = 0;
  XrPosef pose{};
  XrFovf fov{};
};

struct FrameInput {
  std::int64_t frame = 0;
  XrTime display_time = 0;
  std::vector<XrView> views;        // as located for display_time (xrLocateViews)
  std::vector<AppView> app_views;   // the first projection layer's views
  const XrFrameEndInfo* app_frame = nullptr;
};

class FrameRenderer {
 public:
  virtual ~FrameRenderer() = default;
  // Renders the frame; returns the layers to submit instead of the application's (they must
  // stay valid until the next call), or nullptr to submit the application's frame unchanged.
  // Throws on failure; the layer then disables itself for the session.
  virtual const XrFrameEndInfo* render(const FrameInput& in) = 0;
};

// `scene`: env FOVEA_LAYER_SCENE (empty: none). Null when there is nothing to render;
// throws std::runtime_error when a scene is configured but cannot be rendered.
std::unique_ptr<FrameRenderer> make_frame_renderer(const std::string& scene, const VulkanBinding& vk);

}  // namespace fovea::layer
