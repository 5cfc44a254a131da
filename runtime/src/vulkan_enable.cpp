// XR_KHR_vulkan_enable and XR_KHR_vulkan_enable2: graphics requirements, device selection,
// and (enable2) creating the Vulkan instance and device for the application.
#include <cstring>
#include <string>
#include <vector>

#include "api.hpp"
#include "state.hpp"

namespace fovea::runtime {
namespace {

XrResult instance_system(XrInstance instance, XrSystemId system, Instance** out) {
  Instance* inst = find<Instance>(instance);
  if (!inst) return XR_ERROR_HANDLE_INVALID;
  if (system != kSystemId) return XR_ERROR_SYSTEM_INVALID;
  *out = inst;
  return XR_SUCCESS;
}

XrResult requirements(XrInstance instance, XrSystemId systemId, XrGraphicsRequirementsVulkanKHR* req) {
  Instance* inst = nullptr;
  if (XrResult r = instance_system(instance, systemId, &inst); r != XR_SUCCESS) return r;
  if (!has_type(req, XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN_KHR)) return XR_ERROR_VALIDATION_FAILURE;
  req->minApiVersionSupported = XR_MAKE_VERSION(1, 0, 0);
  req->maxApiVersionSupported = XR_MAKE_VERSION(1, 3, 0);
  inst->graphics_requirements_queried = true;
  return XR_SUCCESS;
}

// The simulated HMD is "attached" to the CPU device (lavapipe) when there is one, so runs
// are the same on every machine; otherwise the first device.
XrResult pick_device(VkInstance vk, VkPhysicalDevice* out) {
  if (vk == VK_NULL_HANDLE || !out) return XR_ERROR_VALIDATION_FAILURE;
  uint32_t n = 0;
  if (vkEnumeratePhysicalDevices(vk, &n, nullptr) != VK_SUCCESS || n == 0) return XR_ERROR_RUNTIME_FAILURE;
  std::vector<VkPhysicalDevice> devs(n);
  if (vkEnumeratePhysicalDevices(vk, &n, devs.data()) < 0) return XR_ERROR_RUNTIME_FAILURE;
  *out = devs[0];
  for (VkPhysicalDevice d : devs) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    if (p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) {
      *out = d;
      break;
    }
  }
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(*out, &p);
  FOVEA_LOG_INFO("vulkan: graphics device \"%s\"", p.deviceName);
  return XR_SUCCESS;
}

}  // namespace

XrResult api::xrGetVulkanGraphicsRequirementsKHR(XrInstance instance, XrSystemId systemId,
                                                 XrGraphicsRequirementsVulkanKHR* req) {
  return guarded(__func__, [&] { return requirements(instance, systemId, req); });
}

XrResult api::xrGetVulkanGraphicsRequirements2KHR(XrInstance instance, XrSystemId systemId,
                                                  XrGraphicsRequirementsVulkan2KHR* req) {
  return guarded(__func__, [&] { return requirements(instance, systemId, req); });
}

XrResult api::xrGetVulkanInstanceExtensionsKHR(XrInstance instance, XrSystemId systemId, uint32_t capacity,
                                               uint32_t* count, char* buffer) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = nullptr;
    if (XrResult r = instance_system(instance, systemId, &inst); r != XR_SUCCESS) return r;
    return two_call_string(capacity, count, buffer, "");  // the runtime needs no instance extension
  });
}

XrResult api::xrGetVulkanDeviceExtensionsKHR(XrInstance instance, XrSystemId systemId, uint32_t capacity,
                                             uint32_t* count, char* buffer) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = nullptr;
    if (XrResult r = instance_system(instance, systemId, &inst); r != XR_SUCCESS) return r;
    return two_call_string(capacity, count, buffer, "");  // nor a device extension
  });
}

XrResult api::xrGetVulkanGraphicsDeviceKHR(XrInstance instance, XrSystemId systemId, VkInstance vkInstance,
                                           VkPhysicalDevice* device) {
  return guarded(__func__, [&]() -> XrResult {
    Instance* inst = nullptr;
    if (XrResult r = instance_system(instance, systemId, &inst); r != XR_SUCCESS) return r;
    return pick_device(vkInstance, device);
  });
}

XrResult api::xrGetVulkanGraphicsDevice2KHR(XrInstance instance, const XrVulkanGraphicsDeviceGetInfoKHR* info,
                                            VkPhysicalDevice* device) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Instance>(instance)) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR)) return XR_ERROR_VALIDATION_FAILURE;
    Instance* inst = nullptr;
    if (XrResult r = instance_system(instance, info->systemId, &inst); r != XR_SUCCESS) return r;
    return pick_device(info->vulkanInstance, device);
  });
}

XrResult api::xrCreateVulkanInstanceKHR(XrInstance instance, const XrVulkanInstanceCreateInfoKHR* info,
                                        VkInstance* vkInstance, VkResult* vkResult) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Instance>(instance)) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR) || !vkInstance || !vkResult)
      return XR_ERROR_VALIDATION_FAILURE;
    Instance* inst = nullptr;
    if (XrResult r = instance_system(instance, info->systemId, &inst); r != XR_SUCCESS) return r;
    if (info->createFlags != 0 || !info->pfnGetInstanceProcAddr || !info->vulkanCreateInfo)
      return XR_ERROR_VALIDATION_FAILURE;
    auto create = reinterpret_cast<PFN_vkCreateInstance>(info->pfnGetInstanceProcAddr(nullptr, "vkCreateInstance"));
    if (!create) return XR_ERROR_RUNTIME_FAILURE;
    VkInstanceCreateInfo ci = *info->vulkanCreateInfo;
    std::vector<const char*> layers(ci.ppEnabledLayerNames, ci.ppEnabledLayerNames + ci.enabledLayerCount);
    if (inst->config.vk_validation) {
      // FOVEA_VK_VALIDATION=1: the Khronos validation layer checks the application's and the
      // runtime's Vulkan use; its messages go to the application's debug callback or stdout.
      auto enumerate = reinterpret_cast<PFN_vkEnumerateInstanceLayerProperties>(
          info->pfnGetInstanceProcAddr(nullptr, "vkEnumerateInstanceLayerProperties"));
      uint32_t n = 0;
      std::vector<VkLayerProperties> props;
      if (enumerate && enumerate(&n, nullptr) == VK_SUCCESS) {
        props.resize(n);
        enumerate(&n, props.data());
      }
      const char* kValidation = "VK_LAYER_KHRONOS_validation";
      bool present = false, enabled = false;
      for (const auto& p : props) present |= !std::strcmp(p.layerName, kValidation);
      for (const char* l : layers) enabled |= !std::strcmp(l, kValidation);
      if (present && !enabled) layers.push_back(kValidation);
      FOVEA_LOG_INFO("vulkan: validation layer %s", present ? "enabled" : "requested but not installed");
    }
    ci.enabledLayerCount = uint32_t(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    *vkResult = create(&ci, info->vulkanAllocator, vkInstance);
    if (*vkResult == VK_SUCCESS) inst->vk_instance = *vkInstance;
    FOVEA_LOG_INFO("vulkan: instance created for the application (VkResult %d)", int(*vkResult));
    return XR_SUCCESS;
  });
}

XrResult api::xrCreateVulkanDeviceKHR(XrInstance instance, const XrVulkanDeviceCreateInfoKHR* info,
                                      VkDevice* vkDevice, VkResult* vkResult) {
  return guarded(__func__, [&]() -> XrResult {
    if (!find<Instance>(instance)) return XR_ERROR_HANDLE_INVALID;
    if (!has_type(info, XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR) || !vkDevice || !vkResult)
      return XR_ERROR_VALIDATION_FAILURE;
    Instance* inst = nullptr;
    if (XrResult r = instance_system(instance, info->systemId, &inst); r != XR_SUCCESS) return r;
    if (info->createFlags != 0 || !info->pfnGetInstanceProcAddr || !info->vulkanCreateInfo ||
        info->vulkanPhysicalDevice == VK_NULL_HANDLE)
      return XR_ERROR_VALIDATION_FAILURE;
    if (inst->vk_instance == VK_NULL_HANDLE) return XR_ERROR_CALL_ORDER_INVALID;
    auto create =
        reinterpret_cast<PFN_vkCreateDevice>(info->pfnGetInstanceProcAddr(inst->vk_instance, "vkCreateDevice"));
    if (!create) return XR_ERROR_RUNTIME_FAILURE;
    *vkResult = create(info->vulkanPhysicalDevice, info->vulkanCreateInfo, info->vulkanAllocator, vkDevice);
    FOVEA_LOG_INFO("vulkan: device created for the application (VkResult %d)", int(*vkResult));
    return XR_SUCCESS;
  });
}

}  // namespace fovea::runtime
