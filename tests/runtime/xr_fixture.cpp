#include "xr_fixture.hpp"

#include <cstdlib>
#include <cstring>

namespace fovea::test {

void XrTest::SetUp() {
  setenv("XR_RUNTIME_JSON", FOVEA_RUNTIME_MANIFEST, 1);
  setenv("VK_ICD_FILENAMES", "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json", 0);
  setenv("FOVEA_DISPLAY", "tiny", 1);
  unsetenv("FOVEA_RUNTIME_OUT");
  unsetenv("FOVEA_EXIT_AFTER_FRAMES");
  unsetenv("FOVEA_RUNTIME_PACING");
  unsetenv("XR_ENABLE_API_LAYERS");
}

namespace {

bool g_errors_expected = false;  // see XrTest::expect_validation_errors

VKAPI_ATTR VkBool32 VKAPI_CALL count_errors(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                            VkDebugUtilsMessageTypeFlagsEXT, const VkDebugUtilsMessengerCallbackDataEXT* data,
                                            void* user) {
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    ++*static_cast<int*>(user);
    if (!g_errors_expected) ADD_FAILURE() << "Vulkan validation: " << (data && data->pMessage ? data->pMessage : "");
  }
  return VK_FALSE;
}

}  // namespace

void XrTest::expect_validation_errors(bool expected) { g_errors_expected = expected; }

namespace {

bool validation_requested() {
  const char* v = std::getenv("FOVEA_VK_VALIDATION");
  return v && std::string(v) == "1";
}

}  // namespace

void XrTest::TearDown() { end_instance(); }

void XrTest::end_instance() {
  if (session_) {
    EXPECT_EQ(xrDestroySession(session_), XR_SUCCESS);
  }
  if (vk_device_) vkDestroyDevice(vk_device_, nullptr);
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(vk_instance_, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(vk_instance_, messenger_, nullptr);
  }
  EXPECT_EQ(validation_errors_, 0);
  if (vk_instance_) vkDestroyInstance(vk_instance_, nullptr);
  if (instance_) {
    EXPECT_EQ(xrDestroyInstance(instance_), XR_SUCCESS);
  }
  instance_ = XR_NULL_HANDLE;
  session_ = XR_NULL_HANDLE;
  vk_instance_ = VK_NULL_HANDLE;
  vk_physical_ = VK_NULL_HANDLE;
  vk_device_ = VK_NULL_HANDLE;
  messenger_ = VK_NULL_HANDLE;
}

void XrTest::create_instance(std::vector<const char*> extensions) {
  extensions.push_back(XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME);
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "fovea_runtime_tests");
  ci.applicationInfo.apiVersion = XR_CURRENT_API_VERSION;
  ci.enabledExtensionCount = uint32_t(extensions.size());
  ci.enabledExtensionNames = extensions.data();
  ASSERT_EQ(xrCreateInstance(&ci, &instance_), XR_SUCCESS);
  XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
  gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  ASSERT_EQ(xrGetSystem(instance_, &gi, &system_), XR_SUCCESS);
}

void XrTest::create_session() {
  XrGraphicsRequirementsVulkan2KHR req{XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR};
  ASSERT_EQ(proc<PFN_xrGetVulkanGraphicsRequirements2KHR>("xrGetVulkanGraphicsRequirements2KHR")(instance_, system_, &req),
            XR_SUCCESS);
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.apiVersion = VK_API_VERSION_1_0;
  VkInstanceCreateInfo vci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  vci.pApplicationInfo = &app;
  const char* debug_utils = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  if (validation_requested()) {
    vci.enabledExtensionCount = 1;
    vci.ppEnabledExtensionNames = &debug_utils;
  }
  XrVulkanInstanceCreateInfoKHR xci{XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR};
  xci.systemId = system_;
  xci.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xci.vulkanCreateInfo = &vci;
  VkResult vr = VK_ERROR_UNKNOWN;
  ASSERT_EQ(proc<PFN_xrCreateVulkanInstanceKHR>("xrCreateVulkanInstanceKHR")(instance_, &xci, &vk_instance_, &vr),
            XR_SUCCESS);
  ASSERT_EQ(vr, VK_SUCCESS);
  if (validation_requested()) {
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    mci.pfnUserCallback = &count_errors;
    mci.pUserData = &validation_errors_;
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(vk_instance_, "vkCreateDebugUtilsMessengerEXT"));
    ASSERT_NE(create, nullptr);
    ASSERT_EQ(create(vk_instance_, &mci, nullptr, &messenger_), VK_SUCCESS);
  }
  XrVulkanGraphicsDeviceGetInfoKHR dgi{XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR};
  dgi.systemId = system_;
  dgi.vulkanInstance = vk_instance_;
  ASSERT_EQ(proc<PFN_xrGetVulkanGraphicsDevice2KHR>("xrGetVulkanGraphicsDevice2KHR")(instance_, &dgi, &vk_physical_),
            XR_SUCCESS);
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(vk_physical_, &n, nullptr);
  std::vector<VkQueueFamilyProperties> qf(n);
  vkGetPhysicalDeviceQueueFamilyProperties(vk_physical_, &n, qf.data());
  for (uint32_t i = 0; i < n; ++i)
    if (qf[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
      queue_family_ = i;
      break;
    }
  const float prio = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &prio;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  XrVulkanDeviceCreateInfoKHR xdci{XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR};
  xdci.systemId = system_;
  xdci.pfnGetInstanceProcAddr = &vkGetInstanceProcAddr;
  xdci.vulkanPhysicalDevice = vk_physical_;
  xdci.vulkanCreateInfo = &dci;
  ASSERT_EQ(proc<PFN_xrCreateVulkanDeviceKHR>("xrCreateVulkanDeviceKHR")(instance_, &xdci, &vk_device_, &vr),
            XR_SUCCESS);
  ASSERT_EQ(vr, VK_SUCCESS);
  XrGraphicsBindingVulkan2KHR binding{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  binding.instance = vk_instance_;
  binding.physicalDevice = vk_physical_;
  binding.device = vk_device_;
  binding.queueFamilyIndex = queue_family_;
  binding.queueIndex = 0;
  XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO};
  sci.next = &binding;
  sci.systemId = system_;
  ASSERT_EQ(xrCreateSession(instance_, &sci, &session_), XR_SUCCESS);
}

std::vector<XrSessionState> XrTest::poll_states() {
  std::vector<XrSessionState> states;
  for (;;) {
    XrEventDataBuffer ev{XR_TYPE_EVENT_DATA_BUFFER};
    const XrResult r = xrPollEvent(instance_, &ev);
    EXPECT_TRUE(r == XR_SUCCESS || r == XR_EVENT_UNAVAILABLE) << r;
    if (r != XR_SUCCESS) break;
    if (ev.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED)
      states.push_back(reinterpret_cast<XrEventDataSessionStateChanged*>(&ev)->state);
  }
  return states;
}

void XrTest::run_to_focused() {
  create_session();
  ASSERT_EQ(poll_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY}));
  XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  ASSERT_EQ(xrBeginSession(session_, &bi), XR_SUCCESS);
  ASSERT_EQ(frame(), XR_SUCCESS);
  ASSERT_EQ(poll_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_VISIBLE,
                                                        XR_SESSION_STATE_FOCUSED}));
}

XrResult XrTest::frame(const std::vector<const XrCompositionLayerBaseHeader*>& layers, XrFrameState* state) {
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  if (XrResult r = xrWaitFrame(session_, nullptr, &fs); r != XR_SUCCESS) return r;
  if (state) *state = fs;
  // A frame left open by a failed xrEndFrame is discarded by this xrBeginFrame.
  if (XrResult r = xrBeginFrame(session_, nullptr); r != XR_SUCCESS && r != XR_FRAME_DISCARDED) return r;
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = fs.predictedDisplayTime;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  ei.layerCount = uint32_t(layers.size());
  ei.layers = layers.data();
  return xrEndFrame(session_, &ei);
}

XrPath XrTest::path(const char* s) {
  XrPath p = XR_NULL_PATH;
  EXPECT_EQ(xrStringToPath(instance_, s, &p), XR_SUCCESS) << s;
  return p;
}

XrSpace XrTest::reference_space(XrReferenceSpaceType t, XrPosef pose) {
  XrReferenceSpaceCreateInfo ci{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  ci.referenceSpaceType = t;
  ci.poseInReferenceSpace = pose;
  XrSpace s = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateReferenceSpace(session_, &ci, &s), XR_SUCCESS);
  return s;
}

XrSwapchain XrTest::color_swapchain(uint32_t w, uint32_t h, XrSwapchainUsageFlags usage) {
  XrSwapchainCreateInfo ci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  ci.usageFlags = usage;
  ci.format = VK_FORMAT_R8G8B8A8_SRGB;
  ci.sampleCount = 1;
  ci.width = w;
  ci.height = h;
  ci.faceCount = 1;
  ci.arraySize = 1;
  ci.mipCount = 1;
  XrSwapchain sc = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateSwapchain(session_, &ci, &sc), XR_SUCCESS);
  return sc;
}

}  // namespace fovea::test
