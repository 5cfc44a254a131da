#pragma once
// The path-tracing part of the layer. A FrameRenderer renders the configured scene foveated
// for the views the application submitted (FramePipeline on the application's device or the
// layer's own), composites the application's pixels (composite.hpp), writes the result into
// layer-owned swapchains and returns the frame that replaces the application's.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include "composite.hpp"
#include "config.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "gaze_input.hpp"
#include "layer_queue.hpp"

namespace fovea::layer {

struct Dispatch;

// What the layer added to a Vulkan device the runtime created for the application
// (vulkan_enable.cpp). A device the application created itself (XR_KHR_vulkan_enable) has
// nothing added, as the defaults say.
struct VulkanDeviceRecord {
  static constexpr const char* kMadeByApplication =
      "the application created its Vulkan device itself (XR_KHR_vulkan_enable)";
  // Why VK_KHR_external_memory_fd is not enabled, for the log (empty: it is, and the traced
  // frames reach the device without the host).
  std::string no_external_memory = kMadeByApplication;
  std::optional<QueueIndex> layer_queue;            // the path tracer's queue on the device
  std::string no_layer_queue = kMadeByApplication;  // else why none
  std::uint32_t instance_api_version = 0;           // of the device's instance (0: not known)
  std::vector<std::string> extensions;              // enabled on the device, as far as the layer knows
};

// The application's Vulkan objects, from XrGraphicsBindingVulkan(2)KHR at xrCreateSession.
struct VulkanBinding {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0, queue_index = 0;
  VulkanDeviceRecord added;
  bool external_memory_fd() const { return added.no_external_memory.empty(); }
  bool valid() const { return device != VK_NULL_HANDLE; }
};

// The depth an application chained to a projection view (XrCompositionLayerDepthInfoKHR):
// the depth swapchain's last released image (DEPTH_STENCIL_ATTACHMENT_OPTIMAL) and its range.
struct AppDepth {
  VkImage image = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  XrRect2Di rect{};
  std::uint32_t array_index = 0;
  DepthRange range;
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
  std::optional<AppDepth> depth;  // an XrCompositionLayerDepthInfoKHR was chained
};

struct FrameInput {
  XrTime display_time = 0;
  std::int64_t app_frame_index = 0;  // the application's frame index (its xrWaitFrame count in the session)
  std::vector<AppView> app_views;  // the first stereo projection layer's views
  std::uint32_t projection_layer = 0;  // its index in app_frame->layers
  const XrFrameEndInfo* app_frame = nullptr;
  // The layer's eye-gaze action, once attached. Without it the renderer's devices/ source
  // (FOVEA_GAZE) is used.
  bool gaze_from_action = false;
  ActionGaze action_gaze;
  // The runtime's hidden area (XR_KHR_visibility_mask), when enabled below: fetched for the
  // stereo views when the generation changes (first frame, each change event).
  PFN_xrGetVisibilityMaskKHR get_visibility_mask = nullptr;
  std::uint64_t visibility_mask_generation = 0;
};

// Where the layer's time went in the last render() (milliseconds).
struct RenderTimes {
  double total = 0;     // wall time of the render on the render thread (trace, read-back, encoding)
  double transfer = 0;  // in xrEndFrame: the composition (GPU pass, or read-back, host compositing and upload)
  // The frame driver's step (pipeline/frame_driver.hpp): the pipeline's stages on the GPU and
  // the CPU, and reading the gaze (CPU, monotonic clock); recorded by the names every timing
  // record uses (FrameTimes::gpu_record, cpu_record).
  pipeline::FrameTimes frame;
  double gaze_cpu = 0;
  double readback_cpu = 0;  // CPU: read-back and encoding of the rendered images
  // The gaze sample the frame was foveated for (CLOCK_MONOTONIC ns; 0: none measured yet):
  // when it was measured, when the host received it, when the renderer read it.
  std::int64_t gaze_sample_ns = 0, gaze_receive_ns = 0, gaze_read_ns = 0;
  // gaze_sample_ns and gaze_receive_ns are on the host's CLOCK_MONOTONIC (a live devices/
  // source), else on the runtime's XrTime (the eye-gaze action's XrEyeGazeSampleTimeEXT, or
  // a recorded or synthetic source counted from the first frame's display time).
  bool gaze_on_host_clock = false;
  std::int64_t samples_traced = 0;  // grid cells traced, both eyes
  std::int64_t samples_hidden = 0;  // grid cells under the runtime's hidden area, both eyes: not traced
  // How the traced frame reached the application's device, and the bytes that crossed the
  // host on the way: "application-device" (traced on that device, encoded into the GPU
  // composition's slot there: 0 bytes), "shared-memory" (encoded by the layer's device into the GPU
  // composition's slot, memory of the application's device it imported: 0 bytes),
  // "host-slot" (read back, encoded and written by the host into that slot) or "host" (read
  // back and encoded for the host composition, which uploads its result: those bytes are
  // counted too).
  const char* handover = "";
  std::int64_t host_bytes = 0;
};

// The path-traced frame an xrEndFrame showed.
struct Shown {
  std::int64_t frame = -1;          // its render request's number (-1: none)
  std::int64_t traced_for_ns = 0;   // the display time of the views it was traced for
  std::int64_t traced_for_frame = -1;  // the application's frame index whose views it was traced for
  std::int64_t done_ns = 0;         // when it finished (CLOCK_MONOTONIC)
  double reprojected_deg = 0;       // head rotation since, the larger of the two eyes
  RenderTimes times;                // its render's split; `transfer` is this xrEndFrame's composition
  bool composited_on_gpu = false;   // a compute pass on the application's device (else the host path)
  std::int64_t host_readbacks = 0;  // application images this xrEndFrame copied to the host
  // The GPU path: the traced-frame slot the render thread wrote the shown frame into (-1:
  // none), and the composition's work on the application's thread so far (cumulative):
  // command buffers recorded, descriptor set updates, host waits for a pass in flight
  // (AppDevice::GpuStats).
  int traced_slot = -1;
  std::int64_t recordings = 0, descriptor_updates = 0, reuse_waits = 0, acquire_waits = 0;
  // This xrEndFrame's composition split (ms): the layer's swapchain images acquired and waited
  // for, the composition (the GPU pass's parameters and submission, or the host path), the
  // images released; and the GPU composition's vkQueueSubmit, part of compose_ms.
  double acquire_ms = 0, compose_ms = 0, release_ms = 0, submit_ms = 0;
  std::int64_t submit_preemptions = 0;  // the application's thread lost its core during that vkQueueSubmit
};

// Renders on its own thread: end_frame() hands the submitted views and gaze over and shows
// the newest frame the thread finished; it never waits for a render (unless configured
// "render": "lockstep", for deterministic captures).
class FrameRenderer {
 public:
  virtual ~FrameRenderer() = default;  // stops the render thread after its current frame
  // Returns the layers to submit instead of the application's (valid until the next call):
  // the newest finished path-traced frame, reprojected to the submitted view poses and
  // composited with the application's pixels; nullptr to submit the application's frame
  // unchanged (not a stereo projection, nothing finished yet). Throws on failure, also the
  // render thread's; the layer then disables itself for the session.
  virtual const XrFrameEndInfo* end_frame(const FrameInput& in, Shown& shown) = 0;
  // Waits for the composition passes still reading `image`, an application's swapchain image
  // it has just acquired (a pass runs after xrEndFrame returns); passes on other images keep
  // running. Returns how many it waited for.
  virtual int finish_composition(VkImage image) = 0;
  // Waits for the composition work naming any of `images` and forgets what was recorded for
  // them: before the application destroys their swapchain.
  virtual void forget_images(const std::vector<VkImage>& images) = 0;
};

// Null when no scene is configured; throws when one is configured but cannot be loaded or
// the session has no Vulkan binding. `next` (the layer's table below) must outlive it.
std::unique_ptr<FrameRenderer> make_frame_renderer(const LayerConfig& config, const VulkanBinding& vk,
                                                   const Dispatch& next, XrSession session);

}  // namespace fovea::layer
