#pragma once
// Every OpenXR command the runtime implements, declared once from the registry's PFN types.
// The implementations live in the per-topic files (instance.cpp, session.cpp, ...), inside
// namespace fovea::runtime::api and with hidden visibility: the loader reaches them only
// through xrGetInstanceProcAddr (dispatch.cpp), never by symbol name.
#include <type_traits>

#include "xr.hpp"

// X(name, extension) — extension is the name that must be enabled, or nullptr for core.
#define FOVEA_RUNTIME_COMMANDS(X)                                                     \
  X(xrGetInstanceProcAddr, nullptr)                                                   \
  X(xrEnumerateApiLayerProperties, nullptr)                                           \
  X(xrEnumerateInstanceExtensionProperties, nullptr)                                  \
  X(xrCreateInstance, nullptr)                                                        \
  X(xrDestroyInstance, nullptr)                                                       \
  X(xrGetInstanceProperties, nullptr)                                                 \
  X(xrPollEvent, nullptr)                                                             \
  X(xrResultToString, nullptr)                                                        \
  X(xrStructureTypeToString, nullptr)                                                 \
  X(xrGetSystem, nullptr)                                                             \
  X(xrGetSystemProperties, nullptr)                                                   \
  X(xrEnumerateEnvironmentBlendModes, nullptr)                                        \
  X(xrCreateSession, nullptr)                                                         \
  X(xrDestroySession, nullptr)                                                        \
  X(xrEnumerateReferenceSpaces, nullptr)                                              \
  X(xrCreateReferenceSpace, nullptr)                                                  \
  X(xrGetReferenceSpaceBoundsRect, nullptr)                                           \
  X(xrCreateActionSpace, nullptr)                                                     \
  X(xrLocateSpace, nullptr)                                                           \
  X(xrDestroySpace, nullptr)                                                          \
  X(xrEnumerateViewConfigurations, nullptr)                                           \
  X(xrGetViewConfigurationProperties, nullptr)                                        \
  X(xrEnumerateViewConfigurationViews, nullptr)                                       \
  X(xrEnumerateSwapchainFormats, nullptr)                                             \
  X(xrCreateSwapchain, nullptr)                                                       \
  X(xrDestroySwapchain, nullptr)                                                      \
  X(xrEnumerateSwapchainImages, nullptr)                                              \
  X(xrAcquireSwapchainImage, nullptr)                                                 \
  X(xrWaitSwapchainImage, nullptr)                                                    \
  X(xrReleaseSwapchainImage, nullptr)                                                 \
  X(xrBeginSession, nullptr)                                                          \
  X(xrEndSession, nullptr)                                                            \
  X(xrRequestExitSession, nullptr)                                                    \
  X(xrWaitFrame, nullptr)                                                             \
  X(xrBeginFrame, nullptr)                                                            \
  X(xrEndFrame, nullptr)                                                              \
  X(xrLocateViews, nullptr)                                                           \
  X(xrStringToPath, nullptr)                                                          \
  X(xrPathToString, nullptr)                                                          \
  X(xrCreateActionSet, nullptr)                                                       \
  X(xrDestroyActionSet, nullptr)                                                      \
  X(xrCreateAction, nullptr)                                                          \
  X(xrDestroyAction, nullptr)                                                         \
  X(xrSuggestInteractionProfileBindings, nullptr)                                     \
  X(xrAttachSessionActionSets, nullptr)                                               \
  X(xrGetCurrentInteractionProfile, nullptr)                                          \
  X(xrGetActionStateBoolean, nullptr)                                                 \
  X(xrGetActionStateFloat, nullptr)                                                   \
  X(xrGetActionStateVector2f, nullptr)                                                \
  X(xrGetActionStatePose, nullptr)                                                    \
  X(xrSyncActions, nullptr)                                                           \
  X(xrEnumerateBoundSourcesForAction, nullptr)                                        \
  X(xrGetInputSourceLocalizedName, nullptr)                                           \
  X(xrApplyHapticFeedback, nullptr)                                                   \
  X(xrStopHapticFeedback, nullptr)                                                    \
  X(xrGetVulkanInstanceExtensionsKHR, XR_KHR_VULKAN_ENABLE_EXTENSION_NAME)            \
  X(xrGetVulkanDeviceExtensionsKHR, XR_KHR_VULKAN_ENABLE_EXTENSION_NAME)              \
  X(xrGetVulkanGraphicsDeviceKHR, XR_KHR_VULKAN_ENABLE_EXTENSION_NAME)                \
  X(xrGetVulkanGraphicsRequirementsKHR, XR_KHR_VULKAN_ENABLE_EXTENSION_NAME)          \
  X(xrCreateVulkanInstanceKHR, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME)                  \
  X(xrCreateVulkanDeviceKHR, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME)                    \
  X(xrGetVulkanGraphicsDevice2KHR, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME)              \
  X(xrGetVulkanGraphicsRequirements2KHR, XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME)        \
  X(xrGetVisibilityMaskKHR, XR_KHR_VISIBILITY_MASK_EXTENSION_NAME)                    \
  X(xrConvertTimespecTimeToTimeKHR, XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME)      \
  X(xrConvertTimeToTimespecTimeKHR, XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME)

namespace fovea::runtime::api {

#define FOVEA_RUNTIME_DECLARE(name, ext) std::remove_pointer_t<PFN_##name> name;
FOVEA_RUNTIME_COMMANDS(FOVEA_RUNTIME_DECLARE)
#undef FOVEA_RUNTIME_DECLARE

}  // namespace fovea::runtime::api
