#include "fovea/gpu/context.hpp"
#include "fovea/gpu/memory_type.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "fovea/core/clock.hpp"
#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/error.hpp"

namespace fovea::gpu {

namespace {
// MemAvailable of /proc/meminfo (bytes), else the free physical pages; 0 when unknown.
std::uint64_t host_memory_available() {
  std::ifstream in("/proc/meminfo");
  unsigned long long kib = 0;
  for (std::string line; std::getline(in, line);)
    if (std::sscanf(line.c_str(), "MemAvailable: %llu kB", &kib) == 1) return std::uint64_t(kib) * 1024;
  const long pages = ::sysconf(_SC_AVPHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : 0;
}

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

bool env_flag(const char* name) {
  const char* v = std::getenv(name);
  if (v == nullptr) return false;
  const std::string s(v);
  if (s.empty() || s == "0" || s == "false" || s == "off") return false;
  if (s == "1" || s == "true" || s == "on") return true;
  throw core::InputError(std::string("environment variable ") + name + "='" + s + "': expected 1 or 0");
}

bool has_extension(const std::vector<VkExtensionProperties>& exts, const char* name) {
  for (const auto& e : exts)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

std::vector<VkExtensionProperties> instance_extensions(const char* layer) {
  std::uint32_t n = 0;
  check(vkEnumerateInstanceExtensionProperties(layer, &n, nullptr), "vkEnumerateInstanceExtensionProperties");
  std::vector<VkExtensionProperties> v(n);
  check(vkEnumerateInstanceExtensionProperties(layer, &n, v.data()), "vkEnumerateInstanceExtensionProperties");
  v.resize(n);
  return v;
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_debug_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                VkDebugUtilsMessageTypeFlagsEXT types,
                                                const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* counters = static_cast<ValidationCounters*>(user);
  const bool error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
  // Loader chatter (GENERAL) is logged but only validation findings count.
  const bool counted = (types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT) != 0;
  if (counted) (error ? counters->errors : counters->warnings).fetch_add(1);
  std::fprintf(stderr, "[vulkan %s] %s: %s\n", error ? "error" : "warning",
               data->pMessageIdName != nullptr ? data->pMessageIdName : "(no id)",
               data->pMessage != nullptr ? data->pMessage : "");
  return VK_FALSE;  // never abort the call: the counters decide whether a test fails
}

VkDebugUtilsMessengerCreateInfoEXT messenger_info(ValidationCounters* counters) {
  VkDebugUtilsMessengerCreateInfoEXT ci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  ci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  // Performance hints are not subscribed: they mostly flag VK_IMAGE_LAYOUT_GENERAL,
  // which Fovea uses on purpose (see image.hpp).
  ci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  ci.pfnUserCallback = on_debug_message;
  ci.pUserData = counters;
  return ci;
}

}  // namespace

Context::Context(const ContextOptions& options) {
  const bool validation = options.validation.has_value() ? *options.validation : env_flag("FOVEA_VK_VALIDATION");
  std::string override;
  if (options.device.has_value()) {
    override = *options.device;
  } else if (const char* env = std::getenv("FOVEA_VK_DEVICE")) {
    override = env;
  }
  try {
    create_instance(validation);
    pick_device(override, options);
    create_device(options);
  } catch (...) {
    release();  // the destructor does not run for a constructor that throws
    throw;
  }
}

std::vector<std::string> missing_for_pipeline(const GivenDevice& g) {
  std::vector<std::string> missing;
  const auto version = [](std::uint32_t v) {
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v));
  };
  if (g.instance == VK_NULL_HANDLE || g.physical_device == VK_NULL_HANDLE || g.device == VK_NULL_HANDLE) {
    missing.push_back("an instance, a physical device and a device (a handle is null)");
    return missing;
  }
  if (g.instance_api_version < VK_API_VERSION_1_2)
    missing.push_back("Vulkan 1.2 on the instance (it was created for " + version(g.instance_api_version) + ")");
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(g.physical_device, &p);
  if (p.apiVersion < VK_API_VERSION_1_2)
    missing.push_back(std::string("Vulkan 1.2 on the device (") + p.deviceName + " offers " + version(p.apiVersion) + ")");
  std::uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(g.physical_device, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(g.physical_device, &nq, families.data());
  if (g.queue_family >= nq)
    missing.push_back("queue family " + std::to_string(g.queue_family) + " (the device has " + std::to_string(nq) + ")");
  else if ((families[g.queue_family].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0)
    missing.push_back("compute on queue family " + std::to_string(g.queue_family));
  else if (g.queue_index >= families[g.queue_family].queueCount)
    missing.push_back("queue " + std::to_string(g.queue_index) + " of family " + std::to_string(g.queue_family) +
                      " (it has " + std::to_string(families[g.queue_family].queueCount) + ")");
  if (g.ray_query_features)
    for (const char* e : {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_QUERY_EXTENSION_NAME,
                          VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME})
      if (std::find(g.device_extensions.begin(), g.device_extensions.end(), e) == g.device_extensions.end())
        missing.push_back(std::string("ray queries: ") + e + " enabled on the device");
  return missing;
}

Context::Context(const GivenDevice& given) : owns_device_(false) {
  const std::vector<std::string> missing = missing_for_pipeline(given);
  if (!missing.empty()) {
    std::string m = "the given Vulkan device cannot run the pipeline; it lacks:";
    for (const std::string& s : missing) m += "\n  " + s;
    throw core::InputError(m);
  }
  instance_ = given.instance;
  physical_device_ = given.physical_device;
  device_ = given.device;
  queue_family_ = given.queue_family;
  external_memory_fd_ = std::find(given.device_extensions.begin(), given.device_extensions.end(),
                                  VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME) != given.device_extensions.end();
  describe_device();
  vkGetDeviceQueue(device_, queue_family_, given.queue_index, &queue_);
  if (given.ray_query_features) note_ray_queries();
  try {
    create_command_pool();
  } catch (...) {
    release();
    throw;
  }
}

Context::~Context() { release(); }

void Context::release() {
  if (device_ != VK_NULL_HANDLE) {
    // A given device is its owner's: only what this context made on it goes.
    if (owns_device_) vkDeviceWaitIdle(device_);
    else if (queue_ != VK_NULL_HANDLE) vkQueueWaitIdle(queue_);
    kernels_.clear();
    if (command_pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, command_pool_, nullptr);
    if (owns_device_) vkDestroyDevice(device_, nullptr);
  }
  if (messenger_ != VK_NULL_HANDLE) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance_, messenger_, nullptr);
  }
  if (instance_ != VK_NULL_HANDLE && owns_device_) vkDestroyInstance(instance_, nullptr);
  command_pool_ = VK_NULL_HANDLE;
  device_ = VK_NULL_HANDLE;
  messenger_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

std::shared_ptr<const CompiledKernel> Context::kernel(
    const std::string& key, const std::function<std::shared_ptr<const CompiledKernel>()>& make) {
  const std::lock_guard lock(kernels_mutex_);
  auto& kept = kernels_[key];
  if (!kept) kept = make();  // a throw leaves the entry empty, to be made again
  return kept;
}

void Context::create_instance(bool validation) {
  std::uint32_t version = VK_API_VERSION_1_0;
  check(vkEnumerateInstanceVersion(&version), "vkEnumerateInstanceVersion");
  if (version < VK_API_VERSION_1_2)
    throw std::runtime_error("the Vulkan loader supports Vulkan " + std::to_string(VK_API_VERSION_MAJOR(version)) +
                             "." + std::to_string(VK_API_VERSION_MINOR(version)) + "; Fovea needs 1.2");

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  bool validation_features = false;
  const auto available = instance_extensions(nullptr);
  debug_utils_ = has_extension(available, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  if (validation) {
    std::uint32_t n = 0;
    check(vkEnumerateInstanceLayerProperties(&n, nullptr), "vkEnumerateInstanceLayerProperties");
    std::vector<VkLayerProperties> props(n);
    check(vkEnumerateInstanceLayerProperties(&n, props.data()), "vkEnumerateInstanceLayerProperties");
    bool found = false;
    for (std::uint32_t i = 0; i < n; ++i) found = found || std::strcmp(props[i].layerName, kValidationLayer) == 0;
    if (!found)
      throw core::InputError(std::string("Vulkan validation was requested (FOVEA_VK_VALIDATION=1 or option) but ") +
                             kValidationLayer + " is not installed (Debian package vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    const auto layer_exts = instance_extensions(kValidationLayer);
    debug_utils_ = debug_utils_ || has_extension(layer_exts, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (!debug_utils_)
      throw std::runtime_error("Vulkan validation needs VK_EXT_debug_utils to report its messages; not available");
    validation_features = has_extension(layer_exts, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    if (validation_features) extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
  }
  if (debug_utils_) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "fovea";
  app.pEngineName = "fovea";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ci.pApplicationInfo = &app;
  ci.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  ci.ppEnabledLayerNames = layers.data();
  ci.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  ci.ppEnabledExtensionNames = extensions.data();

  // Chained so that messages from vkCreateInstance/vkDestroyInstance are counted too.
  VkDebugUtilsMessengerCreateInfoEXT messenger_ci = messenger_info(counters_.get());
  // Synchronization validation catches missing barriers between dispatches.
  const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  if (validation) {
    ci.pNext = &messenger_ci;
    if (validation_features) messenger_ci.pNext = &features;
  }
  check(vkCreateInstance(&ci, nullptr, &instance_), "vkCreateInstance");
  validation_ = validation;

  if (validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    const VkDebugUtilsMessengerCreateInfoEXT persistent = messenger_info(counters_.get());
    check(create(instance_, &persistent, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }
  if (debug_utils_)
    set_object_name_ = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        vkGetInstanceProcAddr(instance_, "vkSetDebugUtilsObjectNameEXT"));
}

void Context::pick_device(const std::string& override, const ContextOptions& options) {
  std::uint32_t n = 0;
  check(vkEnumeratePhysicalDevices(instance_, &n, nullptr), "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> devices(n);
  check(vkEnumeratePhysicalDevices(instance_, &n, devices.data()), "vkEnumeratePhysicalDevices");
  devices.resize(n);
  std::vector<DeviceCandidate> candidates;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    std::uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> q(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, q.data());
    bool compute = false;
    for (const auto& f : q) compute = compute || (f.queueFlags & VK_QUEUE_COMPUTE_BIT) != 0;
    candidates.push_back({p.deviceName, p.deviceType, p.apiVersion, compute});
  }
  if (options.device_uuid) {
    // The device another instance uses: the same physical device, whatever this one prefers
    // (still checked for Vulkan 1.2 and a compute queue).
    for (std::size_t i = 0; i < devices.size(); ++i) {
      VkPhysicalDeviceIDProperties id{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES};
      VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &id};
      vkGetPhysicalDeviceProperties2(devices[i], &p2);
      if (std::equal(options.device_uuid->begin(), options.device_uuid->end(), id.deviceUUID)) {
        choose_device(std::span(&candidates[i], 1), "");
        physical_device_ = devices[i];
        return;
      }
    }
    throw core::InputError("no Vulkan device of this process's instance has the device UUID asked for (" +
                           std::to_string(n) + " devices enumerated)");
  }
  physical_device_ = devices[choose_device(candidates, override)];
}

void Context::describe_device() {
  std::uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &nq, families.data());
  VkPhysicalDeviceVulkan12Properties p12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES};
  VkPhysicalDeviceVulkan11Properties p11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES, &p12};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &p11};
  vkGetPhysicalDeviceProperties2(physical_device_, &props);
  limits_ = props.properties.limits;
  vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_);
  if (props.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) host_available_ = host_memory_available();
  info_.name = props.properties.deviceName;
  info_.driver = std::string(p12.driverName) + " " + p12.driverInfo;
  info_.type = props.properties.deviceType;
  info_.api_version = props.properties.apiVersion;
  info_.subgroup_size = p11.subgroupSize;
  info_.subgroup_ballot = (p11.subgroupSupportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
                          (p11.subgroupSupportedOperations & VK_SUBGROUP_FEATURE_BALLOT_BIT) != 0;
  info_.subgroup_arithmetic = (p11.subgroupSupportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
                              (p11.subgroupSupportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) != 0;
  info_.max_shared_memory_bytes = limits_.maxComputeSharedMemorySize;
  info_.max_workgroup_invocations = limits_.maxComputeWorkGroupInvocations;
  for (int i = 0; i < 3; ++i) info_.max_workgroup_size[i] = limits_.maxComputeWorkGroupSize[i];
  info_.max_push_constant_bytes = limits_.maxPushConstantsSize;
  // timestampComputeAndGraphics == false means only some queues support timestamps: trust the family.
  info_.timestamp_valid_bits = families[queue_family_].timestampValidBits;
  info_.timestamp_period_ns = limits_.timestampPeriod;
}

void Context::note_ray_queries() {
  VkPhysicalDeviceAccelerationStructurePropertiesKHR as_props{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &as_props};
  vkGetPhysicalDeviceProperties2(physical_device_, &p2);
  features_.ray_query = true;
  features_.as_scratch_alignment = as_props.minAccelerationStructureScratchOffsetAlignment;
}

void Context::create_command_pool() {
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pci.queueFamilyIndex = queue_family_;
  check(vkCreateCommandPool(device_, &pci, nullptr, &command_pool_), "vkCreateCommandPool");
}

void Context::create_device(const ContextOptions& options) {
  const bool ray_query = options.ray_query;
  // Queue: the first compute family that has timestamps, else the first compute family.
  std::uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &nq, families.data());
  std::optional<std::uint32_t> chosen;
  for (std::uint32_t i = 0; i < nq; ++i) {
    if ((families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) continue;
    if (!chosen || (families[*chosen].timestampValidBits == 0 && families[i].timestampValidBits > 0)) chosen = i;
  }
  queue_family_ = *chosen;  // choose_device guaranteed a compute family
  describe_device();

  // Features: enable only what is supported and useful to compute shaders.
  VkPhysicalDeviceVulkan12Features s12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceVulkan11Features s11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES, &s12};
  VkPhysicalDeviceFeatures2 supported{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &s11};
  vkGetPhysicalDeviceFeatures2(physical_device_, &supported);

  VkPhysicalDeviceVulkan12Features e12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceVulkan11Features e11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES, &e12};
  VkPhysicalDeviceFeatures2 enabled{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &e11};
  e12.shaderInt8 = features_.shader_int8 = s12.shaderInt8;
  e12.shaderFloat16 = features_.shader_float16 = s12.shaderFloat16;
  e12.storageBuffer8BitAccess = features_.storage_buffer_8bit = s12.storageBuffer8BitAccess;
  e12.scalarBlockLayout = features_.scalar_block_layout = s12.scalarBlockLayout;
  e12.timelineSemaphore = features_.timeline_semaphore = s12.timelineSemaphore;
  e11.storageBuffer16BitAccess = features_.storage_buffer_16bit = s11.storageBuffer16BitAccess;
  enabled.features.shaderInt64 = features_.shader_int64 = supported.features.shaderInt64;
  enabled.features.shaderInt16 = features_.shader_int16 = supported.features.shaderInt16;
  enabled.features.shaderStorageImageReadWithoutFormat = features_.storage_image_read_without_format =
      supported.features.shaderStorageImageReadWithoutFormat;
  enabled.features.shaderStorageImageWriteWithoutFormat = features_.storage_image_write_without_format =
      supported.features.shaderStorageImageWriteWithoutFormat;

  std::uint32_t ne = 0;
  check(vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &ne, nullptr),
        "vkEnumerateDeviceExtensionProperties");
  std::vector<VkExtensionProperties> exts(ne);
  check(vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &ne, exts.data()),
        "vkEnumerateDeviceExtensionProperties");
  std::vector<const char*> device_exts;
  // Portability implementations (MoltenVK) require their subset extension to be enabled.
  if (has_extension(exts, "VK_KHR_portability_subset")) device_exts.push_back("VK_KHR_portability_subset");
  if (options.external_memory_fd) {
    if (!has_extension(exts, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME))
      throw core::InputError(info_.name + " has no " VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME
                             ": it cannot share memory with another device");
    device_exts.push_back(VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
    external_memory_fd_ = true;
  }

  // Ray queries: all three extensions and both features, or none (Vulkan 1.2 devices
  // without them keep the compute BVH traversal).
  VkPhysicalDeviceAccelerationStructureFeaturesKHR e_as{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  VkPhysicalDeviceRayQueryFeaturesKHR e_rq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR, &e_as};
  if (ray_query && has_extension(exts, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME) &&
      has_extension(exts, VK_KHR_RAY_QUERY_EXTENSION_NAME) &&
      has_extension(exts, VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME) && s12.bufferDeviceAddress) {
    VkPhysicalDeviceAccelerationStructureFeaturesKHR s_as{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
    VkPhysicalDeviceRayQueryFeaturesKHR s_rq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR, &s_as};
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &s_rq};
    vkGetPhysicalDeviceFeatures2(physical_device_, &f2);
    if (s_as.accelerationStructure && s_rq.rayQuery) {
      note_ray_queries();
      e_as.accelerationStructure = VK_TRUE;
      e_rq.rayQuery = VK_TRUE;
      e12.bufferDeviceAddress = VK_TRUE;
      e12.pNext = &e_rq;
      for (const char* e : {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_QUERY_EXTENSION_NAME,
                            VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME})
        device_exts.push_back(e);
    }
  }

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &enabled};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = static_cast<std::uint32_t>(device_exts.size());
  dci.ppEnabledExtensionNames = device_exts.data();
  check(vkCreateDevice(physical_device_, &dci, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  create_command_pool();
}

void Context::submit_and_wait(const std::function<void(VkCommandBuffer)>& record, double* wait_ms) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = command_pool_;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  check(vkAllocateCommandBuffers(device_, &ai, &cmd), "vkAllocateCommandBuffers");
  VkFence fence = VK_NULL_HANDLE;
  struct Release {  // frees the command buffer and fence however we leave
    Context* ctx;
    VkCommandBuffer& cmd;
    VkFence& fence;
    ~Release() {
      if (fence != VK_NULL_HANDLE) vkDestroyFence(ctx->device_, fence, nullptr);
      vkFreeCommandBuffers(ctx->device_, ctx->command_pool_, 1, &cmd);
    }
  } release{this, cmd, fence};

  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
  // Whole submissions are ordered against earlier device work and later host reads, so
  // callers only need barriers between the commands they record.
  barrier(cmd, access::all_write, access::all);
  record(cmd);
  barrier(cmd, access::all_write, access::all | access::host_read);
  check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");

  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check(vkCreateFence(device_, &fci, nullptr, &fence), "vkCreateFence");
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  check(vkQueueSubmit(queue_, 1, &si, fence), "vkQueueSubmit");
  const core::TimeNs waiting = core::now_ns();
  // Work in flight is never abandoned: freeing its command buffer, or (while an exception
  // unwinds) the buffers it uses, before the device is done is undefined. A bound (600 s
  // before) can run out on a long batch, e.g. a fove0 reference on a loaded CPU device, which
  // finishes eventually; a hung GPU makes the driver report VK_ERROR_DEVICE_LOST instead.
  check(vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  if (wait_ms) *wait_ms = core::ns_to_ms(core::now_ns() - waiting);
}

std::uint32_t Context::memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags required,
                                   VkMemoryPropertyFlags preferred) const {
  const auto type = find_memory_type(memory_, type_bits, required, preferred);
  if (!type) throw VulkanError(VK_ERROR_OUT_OF_DEVICE_MEMORY, "finding a memory type with the required properties");
  return *type;
}

VkDeviceSize Context::memory_type_heap_size(std::uint32_t index) const {
  return memory_.memoryHeaps[memory_.memoryTypes[index].heapIndex].size;
}

VkDeviceSize Context::memory_limit(std::uint32_t memory_type) const {
  const VkDeviceSize heap = memory_type_heap_size(memory_type);
  return host_available_ > 0 ? std::min<VkDeviceSize>(heap, host_available_ / 4 * 3) : heap;
}

VkDeviceSize Context::memory_in_use(std::uint32_t memory_type) const {
  return heap_in_use_[memory_.memoryTypes[memory_type].heapIndex].load();
}

std::vector<Context::HeapUse> Context::heap_use() const {
  std::vector<HeapUse> out;
  for (std::uint32_t h = 0; h < memory_.memoryHeapCount; ++h)
    out.push_back({h, (memory_.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0, memory_.memoryHeaps[h].size,
                   heap_in_use_[h].load(), heap_peak_[h].load()});
  return out;
}

void Context::reset_memory_peaks() {
  for (std::uint32_t h = 0; h < VK_MAX_MEMORY_HEAPS; ++h) heap_peak_[h] = heap_in_use_[h].load();
}

MemoryCharge Context::charge_memory(const std::string& what, VkDeviceSize bytes, std::uint32_t memory_type) {
  const std::uint32_t heap = memory_.memoryTypes[memory_type].heapIndex;
  std::atomic<std::uint64_t>& account = heap_in_use_[heap];
  const std::uint64_t before = account.fetch_add(bytes);
  const VkDeviceSize limit = memory_limit(memory_type);
  if (before + bytes > limit) {
    account.fetch_sub(bytes);
    const auto mib = [](std::uint64_t b) { return std::to_string((b + (1u << 20) - 1) >> 20) + " MiB"; };
    throw core::InputError(what + ": " + mib(bytes) + " more device memory, with " + mib(before) +
                           " already held, is more than this device can give (" + mib(limit) +
                           (host_available_ > 0 ? ": 3/4 of the host memory available to this CPU device" : ": its heap") +
                           "); a smaller display raster, budget or scene fits");
  }
  std::atomic<std::uint64_t>& peak = heap_peak_[heap];
  for (std::uint64_t p = peak.load(); p < before + bytes && !peak.compare_exchange_weak(p, before + bytes);) {
  }
  return MemoryCharge(&account, bytes);
}

VkMemoryPropertyFlags Context::memory_type_flags(std::uint32_t index) const {
  return memory_.memoryTypes[index].propertyFlags;
}

void Context::set_name(VkObjectType type, std::uint64_t handle, const std::string& name) const {
  if (set_object_name_ == nullptr || handle == 0) return;
  VkDebugUtilsObjectNameInfoEXT ni{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  ni.objectType = type;
  ni.objectHandle = handle;
  ni.pObjectName = name.c_str();
  set_object_name_(device_, &ni);
}

}  // namespace fovea::gpu
