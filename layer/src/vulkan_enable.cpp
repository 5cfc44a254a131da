// XR_KHR_vulkan_enable2's xrCreateVulkanInstanceKHR and xrCreateVulkanDeviceKHR: the runtime
// creates the application's Vulkan objects, and the layer adds what the traced frames'
// hand-over without the host needs (frame_renderer.hpp, slot_writer.hpp): Vulkan 1.2 on the
// instance where the loader offers it (what the path tracer needs on the application's device;
// at least 1.1: external memory, dedicated allocations and device UUIDs are core there),
// VK_KHR_external_memory_fd on the device, and a queue for the path tracer where the device
// has one to spare (layer_queue.hpp). Only when a scene is configured for the application and
// its configuration keeps the shared hand-over; everything else is passed down as the
// application gave it. An application written for Vulkan 1.0 runs unchanged on a newer
// instance; the added device extension and queue change nothing it does.
#include <cstring>
#include <string>
#include <vector>

#include "layer.hpp"
#include "layer_queue.hpp"
#include "log.hpp"

namespace fovea::layer {
namespace {

// The runtime's command `name` for the application's instance (null when it has none).
template <class Fn>
Fn next_command(XrInstance instance, const char* name, std::string& application) {
  PFN_xrGetInstanceProcAddr gipa = nullptr;
  {
    std::lock_guard lock(layer().mutex);
    auto it = layer().instances.find(instance);
    if (it == layer().instances.end()) return nullptr;
    gipa = it->second.next.xrGetInstanceProcAddr;
    application = it->second.application;
  }
  PFN_xrVoidFunction fn = nullptr;
  if (XR_FAILED(gipa(instance, name, &fn))) return nullptr;
  return reinterpret_cast<Fn>(fn);
}

// Whether the layer renders for `application` with the shared hand-over; a configuration
// that does not load changes nothing here (the session reports it).
bool wants_shared_memory(const std::string& application) {
  try {
    const LayerConfig c = load_config(application);
    return !c.scene.empty() && c.gpu_compositor && c.shared_handover;
  } catch (const std::exception&) {
    return false;
  }
}

// Empty when VK_KHR_external_memory_fd can be enabled on a device of `physical` (instance
// `vk`, Vulkan `instance_version`); else why not.
std::string external_memory_refusal(PFN_vkGetInstanceProcAddr gipa, VkInstance vk, std::uint32_t instance_version,
                                    VkPhysicalDevice physical) {
  if (instance_version < VK_API_VERSION_1_1)
    return "the application's Vulkan instance is 1.0 (the loader offers no 1.1 to raise it to)";
  const auto props = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties>(gipa(vk, "vkGetPhysicalDeviceProperties"));
  const auto enumerate =
      reinterpret_cast<PFN_vkEnumerateDeviceExtensionProperties>(gipa(vk, "vkEnumerateDeviceExtensionProperties"));
  if (!props || !enumerate) return "the application's Vulkan instance does not resolve the device queries";
  VkPhysicalDeviceProperties p{};
  props(physical, &p);
  if (p.apiVersion < VK_API_VERSION_1_1) return std::string(p.deviceName) + " is a Vulkan 1.0 device";
  std::uint32_t n = 0;
  if (enumerate(physical, nullptr, &n, nullptr) != VK_SUCCESS) return "vkEnumerateDeviceExtensionProperties failed";
  std::vector<VkExtensionProperties> exts(n);
  if (enumerate(physical, nullptr, &n, exts.data()) < 0) return "vkEnumerateDeviceExtensionProperties failed";
  for (std::uint32_t i = 0; i < n; ++i)
    if (!std::strcmp(exts[i].extensionName, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME)) return {};
  return std::string(p.deviceName) + " has no " VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME;
}

}  // namespace

XrResult intercept::xrCreateVulkanInstanceKHR(XrInstance instance, const XrVulkanInstanceCreateInfoKHR* info,
                                              VkInstance* vk_instance, VkResult* vk_result) {
  std::string application;
  const auto next = next_command<PFN_xrCreateVulkanInstanceKHR>(instance, "xrCreateVulkanInstanceKHR", application);
  if (!next) return XR_ERROR_HANDLE_INVALID;
  // Malformed arguments go down unchanged: the runtime answers them.
  if (!info || !info->vulkanCreateInfo || !info->pfnGetInstanceProcAddr || !vk_instance || !vk_result ||
      !wants_shared_memory(application))
    return next(instance, info, vk_instance, vk_result);
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  if (info->vulkanCreateInfo->pApplicationInfo) app = *info->vulkanCreateInfo->pApplicationInfo;
  std::uint32_t version = app.apiVersion == 0 ? VK_API_VERSION_1_0 : app.apiVersion;
  const auto loader_version = reinterpret_cast<PFN_vkEnumerateInstanceVersion>(
      info->pfnGetInstanceProcAddr(VK_NULL_HANDLE, "vkEnumerateInstanceVersion"));
  std::uint32_t available = VK_API_VERSION_1_0;
  if (loader_version && loader_version(&available) != VK_SUCCESS) available = VK_API_VERSION_1_0;
  for (const std::uint32_t wanted : {VK_API_VERSION_1_2, VK_API_VERSION_1_1})
    if (version < wanted && available >= wanted) {
      version = wanted;
      break;
    }
  app.apiVersion = version;
  VkInstanceCreateInfo ci = *info->vulkanCreateInfo;
  ci.pApplicationInfo = &app;
  XrVulkanInstanceCreateInfoKHR changed = *info;
  changed.vulkanCreateInfo = &ci;
  const XrResult r = next(instance, &changed, vk_instance, vk_result);
  if (XR_SUCCEEDED(r) && *vk_result == VK_SUCCESS) {
    std::lock_guard lock(layer().mutex);
    layer().vulkan_instance = *vk_instance;
    layer().vulkan_instance_version = version;
  }
  return r;
}

XrResult intercept::xrCreateVulkanDeviceKHR(XrInstance instance, const XrVulkanDeviceCreateInfoKHR* info,
                                            VkDevice* vk_device, VkResult* vk_result) {
  std::string application;
  const auto next = next_command<PFN_xrCreateVulkanDeviceKHR>(instance, "xrCreateVulkanDeviceKHR", application);
  if (!next) return XR_ERROR_HANDLE_INVALID;
  if (!info || !info->vulkanCreateInfo || !info->pfnGetInstanceProcAddr || !vk_device || !vk_result ||
      info->vulkanPhysicalDevice == VK_NULL_HANDLE || !wants_shared_memory(application))
    return next(instance, info, vk_device, vk_result);
  // The instance the runtime made for the application through the layer (the most recent
  // one: the runtime keeps one per XrInstance).
  VkInstance vk = VK_NULL_HANDLE;
  std::uint32_t version = 0;
  {
    std::lock_guard lock(layer().mutex);
    vk = layer().vulkan_instance;
    version = layer().vulkan_instance_version;
  }
  std::string refusal = vk == VK_NULL_HANDLE
                            ? "the application's Vulkan instance was not created through xrCreateVulkanInstanceKHR"
                            : external_memory_refusal(info->pfnGetInstanceProcAddr, vk, version, info->vulkanPhysicalDevice);
  const VkDeviceCreateInfo& given = *info->vulkanCreateInfo;
  std::vector<const char*> extensions(given.ppEnabledExtensionNames,
                                      given.ppEnabledExtensionNames + given.enabledExtensionCount);
  bool present = false;
  for (const char* e : extensions) present |= !std::strcmp(e, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
  if (refusal.empty() && !present) extensions.push_back(VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
  VkDeviceCreateInfo ci = given;
  ci.enabledExtensionCount = std::uint32_t(extensions.size());
  ci.ppEnabledExtensionNames = extensions.data();
  // The path tracer's own queue on this device: it runs on the same memory as the
  // application's composition, and hands frames over through that shared memory.
  LayerQueueRequest queues;
  if (!refusal.empty()) {
    queues.no_queue = "no shared memory on the device (" + refusal + ")";
  } else {
    const auto family_properties = reinterpret_cast<PFN_vkGetPhysicalDeviceQueueFamilyProperties>(
        info->pfnGetInstanceProcAddr(vk, "vkGetPhysicalDeviceQueueFamilyProperties"));
    std::uint32_t n = 0;
    if (family_properties) family_properties(info->vulkanPhysicalDevice, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    if (n > 0) family_properties(info->vulkanPhysicalDevice, &n, families.data());
    families.resize(n);
    queues = request_layer_queue(families, given.pQueueCreateInfos, given.queueCreateInfoCount);
    ci.queueCreateInfoCount = std::uint32_t(queues.infos.size());
    ci.pQueueCreateInfos = queues.infos.data();
  }
  XrVulkanDeviceCreateInfoKHR changed = *info;
  changed.vulkanCreateInfo = &ci;
  const XrResult r = next(instance, &changed, vk_device, vk_result);
  if (XR_SUCCEEDED(r) && *vk_result == VK_SUCCESS) {
    if (!refusal.empty()) FOVEA_LAYER_INFO("traced frames will cross the host: %s", refusal.c_str());
    if (queues.queue)
      FOVEA_LAYER_INFO("a queue of the application's device for the path tracer: family %u, index %u",
                       queues.queue->family, queues.queue->index);
    else
      FOVEA_LAYER_INFO("no queue of the application's device for the path tracer: %s", queues.no_queue.c_str());
    VulkanDeviceRecord record;
    record.no_external_memory = refusal;
    record.layer_queue = queues.queue;
    record.no_layer_queue = queues.no_queue;
    record.instance_api_version = version;
    record.extensions.assign(extensions.begin(), extensions.end());
    std::lock_guard lock(layer().mutex);
    layer().vulkan_devices[*vk_device] = std::move(record);
  }
  return r;
}

}  // namespace fovea::layer
