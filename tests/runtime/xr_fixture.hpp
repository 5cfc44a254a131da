#pragma once
// GoogleTest fixture: the Fovea runtime through the real OpenXR loader (XR_RUNTIME_JSON
// pointing at the build tree's manifest), with a Vulkan device made through
// XR_KHR_vulkan_enable2 and helpers to drive a session to a given state.
#include <time.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#define XR_USE_GRAPHICS_API_VULKAN
#define XR_USE_TIMESPEC
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

namespace fovea::test {

class XrTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  // Destroys the session, the Vulkan objects and the instance (their records written) and
  // forgets them, ready for another instance in the same test; TearDown does the same.
  void end_instance();

  // Creates instance_ with the given extensions (vulkan_enable2 always) and gets system_.
  void create_instance(std::vector<const char*> extensions = {});
  // Creates the Vulkan instance/device through the runtime and session_ on them.
  void create_session();
  // Polls every queued event; returns the session states seen, in order.
  std::vector<XrSessionState> poll_states();
  // Creates a session and runs it to FOCUSED (one frame with no layers).
  void run_to_focused();
  // xrWaitFrame + xrBeginFrame + xrEndFrame with the given layers.
  XrResult frame(const std::vector<const XrCompositionLayerBaseHeader*>& layers = {}, XrFrameState* state = nullptr);
  template <class F>
  F proc(const char* name) {
    PFN_xrVoidFunction fn = nullptr;
    EXPECT_EQ(xrGetInstanceProcAddr(instance_, name, &fn), XR_SUCCESS) << name;
    return reinterpret_cast<F>(fn);
  }
  XrPath path(const char* s);
  XrSpace reference_space(XrReferenceSpaceType t, XrPosef pose = {{0, 0, 0, 1}, {0, 0, 0}});
  XrSwapchain color_swapchain(uint32_t w, uint32_t h,
                              XrSwapchainUsageFlags usage = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT |
                                                            XR_SWAPCHAIN_USAGE_SAMPLED_BIT);
  // While true, validation errors are counted in validation_errors_ without failing the test
  // (a test that provokes one on purpose checks the count, then resets it).
  void expect_validation_errors(bool expected);

  XrInstance instance_ = XR_NULL_HANDLE;
  XrSystemId system_ = XR_NULL_SYSTEM_ID;
  XrSession session_ = XR_NULL_HANDLE;
  VkInstance vk_instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice vk_physical_ = VK_NULL_HANDLE;
  VkDevice vk_device_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  // FOVEA_VK_VALIDATION=1: the runtime adds the Khronos validation layer to the instance it
  // creates; this messenger counts its errors and a test fails if there were any.
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  int validation_errors_ = 0;
};

}  // namespace fovea::test
