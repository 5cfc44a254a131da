// A Vulkan layer for the tests, VK_LAYER_FOVEA_test_spare_queue: every queue family shows one
// queue more than the driver has, and a queue beyond the driver's is served by the family's
// queue 0 under a lock that every queue command of that queue takes. lavapipe has one queue,
// so without it the Fovea layer could never add a queue of its own to an application's device
// (layer/src/layer_queue.hpp); with it that path runs here, on the same driver. Enabled by
// VK_INSTANCE_LAYERS (above the validation layer an application enables, which sees only the
// driver's queues, used under the lock).
#include <algorithm>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include <vulkan/vk_layer.h>
#include <vulkan/vulkan.h>

namespace {

void* key(const void* dispatchable) { return *static_cast<void* const*>(dispatchable); }

struct Instance {
  PFN_vkGetInstanceProcAddr next = nullptr;
  VkInstance handle = VK_NULL_HANDLE;
};

// A queue beyond the driver's: a dispatchable handle whose first word the loader owns.
struct SpareQueue {
  void* loader_data = nullptr;
};

struct Device {
  PFN_vkGetDeviceProcAddr next = nullptr;
  VkDevice handle = VK_NULL_HANDLE;
  std::map<std::uint32_t, std::uint32_t> created;  // per family, the driver's queues created
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::unique_ptr<SpareQueue>> spares;
};

struct QueueRecord {
  VkQueue real = VK_NULL_HANDLE;
  std::mutex* lock = nullptr;
  Device* device = nullptr;
};

std::mutex g_mutex;
std::map<void*, Instance> g_instances;                   // by dispatch key (physical devices share it)
std::map<void*, std::unique_ptr<Device>> g_devices;      // by dispatch key
std::map<VkQueue, QueueRecord> g_queues;                 // the driver's and the spare ones
std::map<VkQueue, std::unique_ptr<std::mutex>> g_locks;  // per driver queue

template <class Fn>
Fn device_fn(VkDevice d, const char* name) {
  std::lock_guard l(g_mutex);
  const Device& dev = *g_devices.at(key(d));
  return reinterpret_cast<Fn>(dev.next(dev.handle, name));
}
template <class Fn>
Fn queue_fn(VkQueue q, const char* name, QueueRecord& out) {
  std::lock_guard l(g_mutex);
  out = g_queues.at(q);
  return reinterpret_cast<Fn>(out.device->next(out.device->handle, name));
}

VKAPI_ATTR VkResult VKAPI_CALL CreateInstance(const VkInstanceCreateInfo* ci, const VkAllocationCallbacks* a,
                                              VkInstance* out) {
  auto* link = static_cast<const VkLayerInstanceCreateInfo*>(ci->pNext);
  while (link &&
         !(link->sType == VK_STRUCTURE_TYPE_LOADER_INSTANCE_CREATE_INFO && link->function == VK_LAYER_LINK_INFO))
    link = static_cast<const VkLayerInstanceCreateInfo*>(link->pNext);
  if (!link) return VK_ERROR_INITIALIZATION_FAILED;
  const PFN_vkGetInstanceProcAddr next = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  const_cast<VkLayerInstanceCreateInfo*>(link)->u.pLayerInfo = link->u.pLayerInfo->pNext;
  const auto create = reinterpret_cast<PFN_vkCreateInstance>(next(VK_NULL_HANDLE, "vkCreateInstance"));
  const VkResult r = create(ci, a, out);
  if (r == VK_SUCCESS) {
    std::lock_guard l(g_mutex);
    g_instances[key(*out)] = {next, *out};
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyInstance(VkInstance instance, const VkAllocationCallbacks* a) {
  Instance in;
  {
    std::lock_guard l(g_mutex);
    in = g_instances.at(key(instance));
    g_instances.erase(key(instance));
  }
  reinterpret_cast<PFN_vkDestroyInstance>(in.next(in.handle, "vkDestroyInstance"))(instance, a);
}

Instance instance_of(const void* dispatchable) {
  std::lock_guard l(g_mutex);
  return g_instances.at(key(dispatchable));
}

std::uint32_t& count_of(VkQueueFamilyProperties& f) { return f.queueCount; }
std::uint32_t& count_of(VkQueueFamilyProperties2& f) { return f.queueFamilyProperties.queueCount; }

// The driver's families, each with its spare queue.
template <class Fn, class Props>
void family_properties(const char* name, VkPhysicalDevice p, std::uint32_t* n, Props* props) {
  const Instance in = instance_of(p);
  reinterpret_cast<Fn>(in.next(in.handle, name))(p, n, props);
  if (props)
    for (std::uint32_t i = 0; i < *n; ++i) ++count_of(props[i]);
}
VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceQueueFamilyProperties(VkPhysicalDevice p, std::uint32_t* n,
                                                                  VkQueueFamilyProperties* props) {
  family_properties<PFN_vkGetPhysicalDeviceQueueFamilyProperties>("vkGetPhysicalDeviceQueueFamilyProperties", p, n,
                                                                   props);
}
VKAPI_ATTR void VKAPI_CALL GetPhysicalDeviceQueueFamilyProperties2(VkPhysicalDevice p, std::uint32_t* n,
                                                                   VkQueueFamilyProperties2* props) {
  family_properties<PFN_vkGetPhysicalDeviceQueueFamilyProperties2>("vkGetPhysicalDeviceQueueFamilyProperties2", p, n,
                                                                    props);
}

VKAPI_ATTR VkResult VKAPI_CALL CreateDevice(VkPhysicalDevice p, const VkDeviceCreateInfo* ci,
                                            const VkAllocationCallbacks* a, VkDevice* out) {
  auto* link = static_cast<const VkLayerDeviceCreateInfo*>(ci->pNext);
  while (link && !(link->sType == VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO && link->function == VK_LAYER_LINK_INFO))
    link = static_cast<const VkLayerDeviceCreateInfo*>(link->pNext);
  if (!link) return VK_ERROR_INITIALIZATION_FAILED;
  const PFN_vkGetInstanceProcAddr next_instance = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  const PFN_vkGetDeviceProcAddr next_device = link->u.pLayerInfo->pfnNextGetDeviceProcAddr;
  const_cast<VkLayerDeviceCreateInfo*>(link)->u.pLayerInfo = link->u.pLayerInfo->pNext;
  const Instance in = instance_of(p);
  // The driver's counts: the spare queue of each family is not created.
  std::uint32_t nf = 0;
  reinterpret_cast<PFN_vkGetPhysicalDeviceQueueFamilyProperties>(
      in.next(in.handle, "vkGetPhysicalDeviceQueueFamilyProperties"))(p, &nf, nullptr);
  std::vector<VkQueueFamilyProperties> families(nf);
  reinterpret_cast<PFN_vkGetPhysicalDeviceQueueFamilyProperties>(
      in.next(in.handle, "vkGetPhysicalDeviceQueueFamilyProperties"))(p, &nf, families.data());
  std::vector<VkDeviceQueueCreateInfo> queues(ci->pQueueCreateInfos, ci->pQueueCreateInfos + ci->queueCreateInfoCount);
  auto dev = std::make_unique<Device>();
  for (VkDeviceQueueCreateInfo& q : queues)
    if (q.queueFamilyIndex < nf) {
      q.queueCount = std::min(q.queueCount, families[q.queueFamilyIndex].queueCount);
      dev->created[q.queueFamilyIndex] = q.queueCount;
    }
  VkDeviceCreateInfo changed = *ci;
  changed.pQueueCreateInfos = queues.data();
  const auto create = reinterpret_cast<PFN_vkCreateDevice>(next_instance(in.handle, "vkCreateDevice"));
  const VkResult r = create(p, &changed, a, out);
  if (r == VK_SUCCESS) {
    dev->next = next_device;
    dev->handle = *out;
    std::lock_guard l(g_mutex);
    g_devices[key(*out)] = std::move(dev);
  }
  return r;
}

VKAPI_ATTR void VKAPI_CALL DestroyDevice(VkDevice d, const VkAllocationCallbacks* a) {
  const auto destroy = device_fn<PFN_vkDestroyDevice>(d, "vkDestroyDevice");
  {
    std::lock_guard l(g_mutex);
    Device* dev = g_devices.at(key(d)).get();
    for (auto it = g_queues.begin(); it != g_queues.end();)
      it = it->second.device == dev ? g_queues.erase(it) : std::next(it);
    g_devices.erase(key(d));
  }
  destroy(d, a);
}

// The handle for (family, index): the driver's queue, or the spare one served by queue 0.
VkQueue queue_for(VkDevice d, std::uint32_t family, std::uint32_t index, VkQueue real_queue_0) {
  std::lock_guard l(g_mutex);
  Device& dev = *g_devices.at(key(d));
  VkQueue handle = real_queue_0;
  if (index >= dev.created[family]) {
    auto& spare = dev.spares[{family, index}];
    if (!spare) spare = std::make_unique<SpareQueue>();
    spare->loader_data = key(d);  // what the loader sets for a queue of this device
    handle = reinterpret_cast<VkQueue>(spare.get());
  }
  auto& lock = g_locks[real_queue_0];
  if (!lock) lock = std::make_unique<std::mutex>();
  g_queues[handle] = {real_queue_0, lock.get(), &dev};
  return handle;
}

VKAPI_ATTR void VKAPI_CALL GetDeviceQueue(VkDevice d, std::uint32_t family, std::uint32_t index, VkQueue* out) {
  const auto get = device_fn<PFN_vkGetDeviceQueue>(d, "vkGetDeviceQueue");
  std::uint32_t created = 0;
  {
    std::lock_guard l(g_mutex);
    created = g_devices.at(key(d))->created[family];
  }
  VkQueue real = VK_NULL_HANDLE;
  get(d, family, index < created ? index : 0, &real);
  // The loader writes its dispatch into the queues it hands out: this one may never pass it,
  // and the layers below find a queue's device by that word.
  *reinterpret_cast<void**>(real) = key(d);
  if (index < created) {
    std::lock_guard l(g_mutex);
    auto& lock = g_locks[real];
    if (!lock) lock = std::make_unique<std::mutex>();
    g_queues[real] = {real, lock.get(), g_devices.at(key(d)).get()};
    *out = real;
    return;
  }
  *out = queue_for(d, family, index, real);
}

VKAPI_ATTR void VKAPI_CALL GetDeviceQueue2(VkDevice d, const VkDeviceQueueInfo2* info, VkQueue* out) {
  if (info->flags != 0) {  // protected queues: the driver's only
    device_fn<PFN_vkGetDeviceQueue2>(d, "vkGetDeviceQueue2")(d, info, out);
    return;
  }
  GetDeviceQueue(d, info->queueFamilyIndex, info->queueIndex, out);
}

VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit(VkQueue q, std::uint32_t n, const VkSubmitInfo* s, VkFence f) {
  QueueRecord r;
  const auto fn = queue_fn<PFN_vkQueueSubmit>(q, "vkQueueSubmit", r);
  std::lock_guard l(*r.lock);
  return fn(r.real, n, s, f);
}
VKAPI_ATTR VkResult VKAPI_CALL QueueSubmit2(VkQueue q, std::uint32_t n, const VkSubmitInfo2* s, VkFence f) {
  QueueRecord r;
  const auto fn = queue_fn<PFN_vkQueueSubmit2>(q, "vkQueueSubmit2", r);
  std::lock_guard l(*r.lock);
  return fn(r.real, n, s, f);
}
VKAPI_ATTR VkResult VKAPI_CALL QueueWaitIdle(VkQueue q) {
  QueueRecord r;
  const auto fn = queue_fn<PFN_vkQueueWaitIdle>(q, "vkQueueWaitIdle", r);
  std::lock_guard l(*r.lock);
  return fn(r.real);
}
VKAPI_ATTR VkResult VKAPI_CALL QueueBindSparse(VkQueue q, std::uint32_t n, const VkBindSparseInfo* b, VkFence f) {
  QueueRecord r;
  const auto fn = queue_fn<PFN_vkQueueBindSparse>(q, "vkQueueBindSparse", r);
  std::lock_guard l(*r.lock);
  return fn(r.real, n, b, f);
}
VKAPI_ATTR void VKAPI_CALL QueueBeginDebugUtilsLabelEXT(VkQueue q, const VkDebugUtilsLabelEXT* label) {
  QueueRecord r;
  const auto fn = queue_fn<PFN_vkQueueBeginDebugUtilsLabelEXT>(q, "vkQueueBeginDebugUtilsLabelEXT", r);
  std::lock_guard l(*r.lock);
  fn(r.real, label);
}
VKAPI_ATTR void VKAPI_CALL QueueEndDebugUtilsLabelEXT(VkQueue q) {
  QueueRecord r;
  const auto fn = queue_fn<PFN_vkQueueEndDebugUtilsLabelEXT>(q, "vkQueueEndDebugUtilsLabelEXT", r);
  std::lock_guard l(*r.lock);
  fn(r.real);
}
VKAPI_ATTR void VKAPI_CALL QueueInsertDebugUtilsLabelEXT(VkQueue q, const VkDebugUtilsLabelEXT* label) {
  QueueRecord r;
  const auto fn = queue_fn<PFN_vkQueueInsertDebugUtilsLabelEXT>(q, "vkQueueInsertDebugUtilsLabelEXT", r);
  std::lock_guard l(*r.lock);
  fn(r.real, label);
}
// A spare queue's name would name the driver's queue: it keeps its own.
VKAPI_ATTR VkResult VKAPI_CALL SetDebugUtilsObjectNameEXT(VkDevice d, const VkDebugUtilsObjectNameInfoEXT* info) {
  const auto fn = device_fn<PFN_vkSetDebugUtilsObjectNameEXT>(d, "vkSetDebugUtilsObjectNameEXT");
  if (info->objectType == VK_OBJECT_TYPE_QUEUE) {
    std::lock_guard l(g_mutex);
    const auto it = g_queues.find(reinterpret_cast<VkQueue>(info->objectHandle));
    if (it != g_queues.end() && it->second.real != it->first) return VK_SUCCESS;
  }
  return fn(d, info);
}

using Command = std::pair<const char*, PFN_vkVoidFunction>;
template <class Fn>
Command command(const char* name, Fn fn) {
  return {name, reinterpret_cast<PFN_vkVoidFunction>(fn)};
}
template <std::size_t N>
PFN_vkVoidFunction find(const Command (&commands)[N], const char* name) {
  for (const auto& [n, fn] : commands)
    if (!std::strcmp(n, name)) return fn;
  return nullptr;
}

PFN_vkVoidFunction device_command(const char* name) {
  static const Command kCommands[] = {
      command("vkGetDeviceQueue", GetDeviceQueue),
      command("vkGetDeviceQueue2", GetDeviceQueue2),
      command("vkDestroyDevice", DestroyDevice),
      command("vkQueueSubmit", QueueSubmit),
      command("vkQueueSubmit2", QueueSubmit2),
      command("vkQueueSubmit2KHR", QueueSubmit2),
      command("vkQueueWaitIdle", QueueWaitIdle),
      command("vkQueueBindSparse", QueueBindSparse),
      command("vkQueueBeginDebugUtilsLabelEXT", QueueBeginDebugUtilsLabelEXT),
      command("vkQueueEndDebugUtilsLabelEXT", QueueEndDebugUtilsLabelEXT),
      command("vkQueueInsertDebugUtilsLabelEXT", QueueInsertDebugUtilsLabelEXT),
      command("vkSetDebugUtilsObjectNameEXT", SetDebugUtilsObjectNameEXT),
  };
  return find(kCommands, name);
}

// This layer's command where the chain below offers `name` (`next`): a command the driver
// lacks stays absent.
PFN_vkVoidFunction over(PFN_vkVoidFunction next, const char* name) {
  const PFN_vkVoidFunction mine = next ? device_command(name) : nullptr;
  return mine ? mine : next;
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetDeviceProcAddr(VkDevice d, const char* name) {
  PFN_vkVoidFunction next = nullptr;
  {
    std::lock_guard l(g_mutex);
    const Device& dev = *g_devices.at(key(d));
    next = dev.next(dev.handle, name);
  }
  return over(next, name);
}

VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL GetInstanceProcAddr(VkInstance instance, const char* name) {
  static const Command kCommands[] = {
      command("vkGetInstanceProcAddr", GetInstanceProcAddr),
      command("vkGetDeviceProcAddr", GetDeviceProcAddr),
      command("vkCreateInstance", CreateInstance),
      command("vkDestroyInstance", DestroyInstance),
      command("vkCreateDevice", CreateDevice),
      command("vkGetPhysicalDeviceQueueFamilyProperties", GetPhysicalDeviceQueueFamilyProperties),
      command("vkGetPhysicalDeviceQueueFamilyProperties2", GetPhysicalDeviceQueueFamilyProperties2),
      command("vkGetPhysicalDeviceQueueFamilyProperties2KHR", GetPhysicalDeviceQueueFamilyProperties2),
  };
  if (const PFN_vkVoidFunction mine = find(kCommands, name)) return mine;
  if (instance == VK_NULL_HANDLE) return nullptr;
  const Instance in = instance_of(instance);
  return over(in.next(in.handle, name), name);
}

}  // namespace

extern "C" __attribute__((visibility("default"))) VKAPI_ATTR VkResult VKAPI_CALL
vkNegotiateLoaderLayerInterfaceVersion(VkNegotiateLayerInterface* v) {
  if (!v || v->sType != LAYER_NEGOTIATE_INTERFACE_STRUCT) return VK_ERROR_INITIALIZATION_FAILED;
  if (v->loaderLayerInterfaceVersion > 2) v->loaderLayerInterfaceVersion = 2;
  v->pfnGetInstanceProcAddr = GetInstanceProcAddr;
  v->pfnGetDeviceProcAddr = GetDeviceProcAddr;
  v->pfnGetPhysicalDeviceProcAddr = nullptr;
  return VK_SUCCESS;
}
