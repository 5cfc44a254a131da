#pragma once
// XR_APILAYER_FOVEA_path_tracing: state shared by the layer's entry points. The layer sits
// between the application and the runtime; every call it does not need passes straight
// through (it never appears in the layer's xrGetInstanceProcAddr), and the ones it
// intercepts are always forwarded exactly once with the application's arguments unless a
// frame renderer is active (frame_renderer.hpp).
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <time.h>

#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include "eye_gaze.hpp"
#include "fovea/xrcommon/loader_interface.hpp"
#include "frame_log.hpp"
#include "frame_queue.hpp"
#include "frame_renderer.hpp"

namespace fovea::layer {

constexpr const char* kLayerName = "XR_APILAYER_FOVEA_path_tracing";
// The layer's own instance extension, advertised so applications can tell the layer is
// present; rendering is switched on by the configuration (config.hpp). Never passed down.
constexpr const char* kLayerExtension = "XR_FOVEA_path_tracing";
constexpr std::uint32_t kLayerExtensionVersion = 1;
// Enabled below the layer, when the runtime offers it and a scene is configured, for the
// runtime's hidden area (the view pixels the layer does not trace).
constexpr const char* kVisibilityMaskExtension = "XR_KHR_visibility_mask";
// Enabled below the layer, when the runtime offers it and FOVEA_LAYER_OUT is set, so the
// runtime's XrTime values in layer_timing.jsonl are converted to CLOCK_MONOTONIC, the clock of
// the layer's own stamps (an XrTime need not be CLOCK_MONOTONIC: Monado's is not).
constexpr const char* kConvertTimespecExtension = "XR_KHR_convert_timespec_time";
// PFN_xrConvertTimeToTimespecTimeKHR, declared here: openxr_platform.h declares it only when
// XR_USE_TIMESPEC was defined before its first inclusion, wherever that was.
using ConvertTimeToTimespec = XrResult(XRAPI_PTR*)(XrInstance instance, XrTime time, struct timespec* timespecTime);

// The next layer's (or the runtime's) commands the layer calls.
#define FOVEA_LAYER_NEXT(X) \
  X(xrGetInstanceProcAddr)  \
  X(xrDestroyInstance)      \
  X(xrCreateSession)        \
  X(xrDestroySession)       \
  X(xrCreateSwapchain)      \
  X(xrDestroySwapchain)     \
  X(xrEnumerateSwapchainImages) \
  X(xrAcquireSwapchainImage) \
  X(xrWaitSwapchainImage)    \
  X(xrReleaseSwapchainImage) \
  X(xrWaitFrame)            \
  X(xrBeginFrame)           \
  X(xrEndFrame)              \
  X(xrCreateActionSet)       \
  X(xrDestroyActionSet)      \
  X(xrCreateAction)          \
  X(xrDestroyAction)         \
  X(xrStringToPath)          \
  X(xrSuggestInteractionProfileBindings) \
  X(xrAttachSessionActionSets) \
  X(xrSyncActions)           \
  X(xrCreateActionSpace)     \
  X(xrCreateReferenceSpace)  \
  X(xrLocateSpace)           \
  X(xrDestroySpace)          \
  X(xrPollEvent)             \
  X(xrGetSystemProperties)   \
  X(xrGetCurrentInteractionProfile)

struct Dispatch {
#define FOVEA_LAYER_MEMBER(name) PFN_##name name = nullptr;
  FOVEA_LAYER_NEXT(FOVEA_LAYER_MEMBER)
#undef FOVEA_LAYER_MEMBER
};

struct SwapchainState {
  XrSession session = XR_NULL_HANDLE;
  XrSwapchainCreateInfo info{};
  std::vector<VkImage> images;
  std::vector<std::uint32_t> acquired;
  std::int64_t last_released = -1;
};

// A session's frame loop records: the queue under the session's own lock (held only for
// bookkeeping, never across a render or a call down the chain); the log has its own.
struct SessionFrames {
  std::mutex mutex;
  FrameQueue queue;
  FrameLog log;
};

// Fields are read and written under Layer::mutex, held briefly; the renderer and the frame
// records are shared so that the calls using them run outside it.
struct SessionState {
  XrInstance instance = XR_NULL_HANDLE;
  bool disabled = false;  // an internal failure: pass everything through from then on
  VulkanBinding vulkan;
  std::shared_ptr<FrameRenderer> renderer;  // null: pass-through, measure only
  std::shared_ptr<SessionFrames> frames = std::make_shared<SessionFrames>();
  EyeGazeSession gaze;                    // after an attach that included the layer's action set
  // The interaction profiles the application has seen for InstanceState::app_user_paths (the
  // layer's binding hidden); a profile-changed event that changes none of them is the layer's.
  std::vector<XrPath> app_profiles;
  // The runtime's xrGetVisibilityMaskKHR (null: not enabled below); the generation counts the
  // XR_TYPE_EVENT_DATA_VISIBILITY_MASK_CHANGED_KHR events seen, so the renderer re-fetches.
  PFN_xrGetVisibilityMaskKHR get_visibility_mask = nullptr;
  std::uint64_t visibility_mask_generation = 0;
};

struct InstanceState {
  Dispatch next;
  bool extension_enabled = false;  // the application enabled kLayerExtension
  std::string application;         // XrApplicationInfo::applicationName (the config section)
  EyeGazeActions gaze;             // the layer's eye-gaze action (a scene configured, the runtime has it)
  // The layer enabled XR_EXT_eye_gaze_interaction for itself: for the application it stays
  // not enabled (its profile, top-level path and properties unsupported or absent).
  bool gaze_hidden = false;
  // The application's own suggestion for the eye-gaze profile succeeded: its binding, not only
  // the layer's, makes the profile current.
  bool app_suggested_gaze = false;
  std::vector<XrPath> app_user_paths;  // the top-level user paths the application can query
  PFN_xrGetVisibilityMaskKHR get_visibility_mask = nullptr;  // the extension is enabled below
  // The layer enabled kVisibilityMaskExtension for itself: the application must not see it
  // (its command stays unsupported, its events are not delivered).
  bool visibility_mask_hidden = false;
  // The runtime's xrConvertTimeToTimespecTimeKHR (null: the extension is not enabled below);
  // hidden from an application that did not enable the extension itself.
  ConvertTimeToTimespec to_timespec = nullptr;
  bool timespec_hidden = false;
};

struct Layer {
  std::mutex mutex;
  std::map<XrInstance, InstanceState> instances;
  std::map<XrSession, SessionState> sessions;
  std::map<XrSwapchain, SwapchainState> swapchains;
  std::map<XrActionSet, XrInstance> action_sets;  // the application's, for xrCreateAction's instance
  XrInstance last_instance = XR_NULL_HANDLE;  // dispatch for handles the layer does not know
  // The Vulkan objects the runtime created for the application through the layer
  // (XR_KHR_vulkan_enable2, vulkan_enable.cpp): the last instance and its API version, and
  // per device what the layer added to it.
  VkInstance vulkan_instance = VK_NULL_HANDLE;
  std::uint32_t vulkan_instance_version = 0;
  std::map<VkDevice, VulkanDeviceRecord> vulkan_devices;
};

Layer& layer();

// What the loader negotiation hands the loader (instance.cpp).
XrResult XRAPI_CALL get_instance_proc_addr(XrInstance instance, const char* name, PFN_xrVoidFunction* function);
XrResult XRAPI_CALL create_api_layer_instance(const XrInstanceCreateInfo* info, const XrApiLayerCreateInfo* layer_info,
                                              XrInstance* instance);

// The next layer's table for the instance owning `session`; for an unknown session (the
// application's mistake) the most recent instance's, so the runtime reports the error.
const Dispatch* next_for_session(XrSession session);

// Destroys what the layer created on a session's handles (the eye-gaze spaces) and returns
// its renderer, for the caller to release outside Layer::mutex (that joins the render thread
// and destroys the renderer's swapchains and its objects on the application's device) before
// the session, or its instance, is destroyed below the layer. The session passes through
// from then on.
[[nodiscard]] std::shared_ptr<FrameRenderer> release_session(SessionState& s, const Dispatch& next);

// Whether an interaction-profile-changed event of `session` changed nothing the application
// can see (the layer's eye-gaze binding caused it); updates what the application has seen.
bool layer_caused_profile_change(XrSession session);

// Intercepted commands (hidden; reached through the layer's xrGetInstanceProcAddr).
namespace intercept {
#define FOVEA_LAYER_INTERCEPTED(X) \
  X(xrDestroyInstance)             \
  X(xrCreateSession)               \
  X(xrDestroySession)              \
  X(xrCreateSwapchain)             \
  X(xrDestroySwapchain)            \
  X(xrAcquireSwapchainImage)       \
  X(xrReleaseSwapchainImage)       \
  X(xrWaitFrame)                   \
  X(xrBeginFrame)                  \
  X(xrEndFrame)                    \
  X(xrSuggestInteractionProfileBindings) \
  X(xrCreateActionSet)             \
  X(xrDestroyActionSet)            \
  X(xrCreateAction)                \
  X(xrAttachSessionActionSets)     \
  X(xrSyncActions)                 \
  X(xrPollEvent)                   \
  X(xrGetSystemProperties)         \
  X(xrGetCurrentInteractionProfile) \
  X(xrCreateVulkanInstanceKHR)     \
  X(xrCreateVulkanDeviceKHR)
#define FOVEA_LAYER_DECLARE(name) std::remove_pointer_t<PFN_##name> name;
FOVEA_LAYER_INTERCEPTED(FOVEA_LAYER_DECLARE)
#undef FOVEA_LAYER_DECLARE
}  // namespace intercept

}  // namespace fovea::layer
