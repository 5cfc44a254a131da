#pragma once
// Headless Vulkan 1.2 compute context: instance, one physical device, one
// compute-capable queue, a transient command pool. No window system.
//
// Device choice: env FOVEA_VK_DEVICE (case-insensitive substring of the device name)
// or ContextOptions::device; otherwise discrete > integrated > virtual > CPU.
// Validation: env FOVEA_VK_VALIDATION=1 or ContextOptions::validation enables
// VK_LAYER_KHRONOS_validation (with synchronization validation) and a messenger that
// counts errors and warnings and logs them to stderr with their message id.
//
// A Context is neither copyable nor movable: resources keep a pointer to it and must
// be destroyed before it. It is meant to be used from one thread at a time.
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <vulkan/vulkan_core.h>

#include "fovea/gpu/memory_charge.hpp"

namespace fovea::gpu {

struct ContextOptions {
  // Unset: read env FOVEA_VK_VALIDATION ("1"/"0"). True and the layer absent -> error.
  std::optional<bool> validation;
  // Unset: read env FOVEA_VK_DEVICE. Empty: automatic choice.
  std::optional<std::string> device;
  // Ray queries (VK_KHR_acceleration_structure + VK_KHR_ray_query) are enabled when the
  // device offers them; false leaves them off, as on a device without them.
  bool ray_query = true;
  // The physical device whose VkPhysicalDeviceIDProperties::deviceUUID this is (another
  // instance's device in the process, whose memory the Context is to share): chosen over
  // `device` and FOVEA_VK_DEVICE. Throws core::InputError when no device has it.
  std::optional<std::array<std::uint8_t, VK_UUID_SIZE>> device_uuid;
  // Enable VK_KHR_external_memory_fd: memory another device of the same physical device
  // exported as an opaque file descriptor is imported (BufferDesc::imported). Throws
  // core::InputError when the device lacks it.
  bool external_memory_fd = false;
};

// A Vulkan device made elsewhere in the process (an OpenXR application's, or another
// Context's) for a Context to run on without owning it (as Monado's vk_init_from_given):
// the handles, the queue to submit to — which nobody else may use while the Context does —
// and what was enabled on them, which Vulkan cannot be asked afterwards.
struct GivenDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0;
  std::uint32_t queue_index = 0;
  std::uint32_t instance_api_version = VK_API_VERSION_1_0;  // VkApplicationInfo::apiVersion of the instance
  // Enabled on `device`; with VK_KHR_external_memory_fd among them the Context imports memory
  // (BufferDesc::imported), also memory this same device exported.
  std::vector<std::string> device_extensions;
  // accelerationStructure, rayQuery and bufferDeviceAddress were enabled (with the three
  // extensions): the path tracer may use ray queries.
  bool ray_query_features = false;
};

// What the pipeline needs that `given` lacks, one line each (empty: it can run there):
// Vulkan 1.2 on the instance and the device, a queue of a compute-capable family.
std::vector<std::string> missing_for_pipeline(const GivenDevice& given);

// Counters of validation messages, shared so they can be read after the context
// (and its device) is gone: errors at vkDestroyDevice are counted too.
struct ValidationCounters {
  std::atomic<std::int64_t> errors{0};
  std::atomic<std::int64_t> warnings{0};
};

// What the device-choice logic needs to know about one physical device.
struct DeviceCandidate {
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::uint32_t api_version = 0;
  bool has_compute_queue = false;
};

// Index of the device to use: the first candidate whose name contains `override`
// (case-insensitive) when it is non-empty, else the best type. Throws core::InputError
// listing every device when nothing matches, the match lacks Vulkan 1.2 or a compute
// queue, or the list is empty.
std::size_t choose_device(std::span<const DeviceCandidate> candidates, std::string_view override);

// Properties of the chosen device that shader authors and reports care about.
struct DeviceInfo {
  std::string name;
  std::string driver;  // driver name and info, e.g. "llvmpipe Mesa 22.3.6 (LLVM 15.0.6)"
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::uint32_t api_version = 0;
  std::uint32_t subgroup_size = 0;
  bool subgroup_ballot = false;  // compute shaders have subgroup ballots (and elect, broadcast)
  bool subgroup_arithmetic = false;  // compute shaders have subgroup arithmetic (subgroupAdd, subgroupMax)
  std::uint32_t max_shared_memory_bytes = 0;
  std::uint32_t max_workgroup_invocations = 0;
  std::uint32_t max_workgroup_size[3] = {0, 0, 0};
  std::uint32_t max_push_constant_bytes = 0;
  std::uint32_t timestamp_valid_bits = 0;  // on the chosen queue; 0 = no timestamps
  double timestamp_period_ns = 0;          // ns per timestamp tick
};

// Optional features, enabled only when the device supports them.
struct EnabledFeatures {
  bool shader_int64 = false;
  bool shader_int16 = false;
  bool shader_int8 = false;
  bool shader_float16 = false;
  bool storage_buffer_8bit = false;
  bool storage_buffer_16bit = false;
  bool scalar_block_layout = false;
  bool storage_image_read_without_format = false;
  bool storage_image_write_without_format = false;
  bool timeline_semaphore = false;
  // VK_KHR_acceleration_structure + VK_KHR_ray_query + VK_KHR_deferred_host_operations with
  // bufferDeviceAddress: compute shaders may trace rays through acceleration structures.
  bool ray_query = false;
  std::uint32_t as_scratch_alignment = 0;  // minAccelerationStructureScratchOffsetAlignment
};

struct CompiledKernel;  // pipeline.hpp

class Context {
 public:
  explicit Context(const ContextOptions& options = {});
  // Runs on a device made elsewhere, which the Context neither owns nor destroys (it makes
  // and destroys its own command pool only). Throws core::InputError listing everything
  // missing_for_pipeline() finds. Validation messages are the instance owner's to count.
  explicit Context(const GivenDevice& given);
  ~Context();
  bool owns_device() const { return owns_device_; }
  bool external_memory_fd() const { return external_memory_fd_; }  // ContextOptions::external_memory_fd, or given
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queue_family() const { return queue_family_; }
  const DeviceInfo& info() const { return info_; }
  const VkPhysicalDeviceLimits& limits() const { return limits_; }
  const EnabledFeatures& features() const { return features_; }
  bool timestamps_supported() const { return info_.timestamp_valid_bits > 0; }

  bool validation_enabled() const { return validation_; }
  std::int64_t validation_errors() const { return counters_->errors.load(); }
  std::int64_t validation_warnings() const { return counters_->warnings.load(); }
  std::shared_ptr<const ValidationCounters> validation_counters() const { return counters_; }

  // Records `record` into a fresh primary command buffer, submits it and waits for it.
  // Calls may nest (an upload inside `record` completes before the outer submission).
  // `wait_ms`, when given, receives the time spent in the fence wait alone (monotonic clock).
  void submit_and_wait(const std::function<void(VkCommandBuffer)>& record, double* wait_ms = nullptr);

  // Index of a memory type allowed by `type_bits` having all of `required`, preferring
  // one that also has `preferred`; throws VulkanError when there is none.
  std::uint32_t memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags required,
                            VkMemoryPropertyFlags preferred = 0) const;
  VkMemoryPropertyFlags memory_type_flags(std::uint32_t index) const;
  const VkPhysicalDeviceMemoryProperties& memory_types() const { return memory_; }
  // Size of the heap that memory type `index` allocates from, bytes.
  VkDeviceSize memory_type_heap_size(std::uint32_t index) const;
  // The most device memory this context's buffers and images may hold in that heap: the
  // heap's size, and on a CPU device (whose device memory is the process's) at most 3/4 of
  // the host memory available when the context was created, so that an input too large for
  // the machine is refused before the system runs out (a render at 8192x8192 per eye on a
  // 24 GB machine was killed by the kernel's out-of-memory killer instead).
  VkDeviceSize memory_limit(std::uint32_t memory_type) const;
  // Charges `bytes` of memory type `memory_type` for `what` before it is allocated; throws
  // core::InputError naming what, the sizes and the limit when it would pass memory_limit.
  MemoryCharge charge_memory(const std::string& what, VkDeviceSize bytes, std::uint32_t memory_type);
  VkDeviceSize memory_in_use(std::uint32_t memory_type) const;
  // Each memory heap of the device: its size, what this context's buffers and images hold in
  // it now (charge_memory) and the most they held at once since the context was made or
  // reset_memory_peaks.
  struct HeapUse {
    std::uint32_t heap = 0;
    bool device_local = false;
    VkDeviceSize size = 0, held = 0, peak = 0;
  };
  std::vector<HeapUse> heap_use() const;
  // Starts the peaks over from what is held now (to measure one phase of a run).
  void reset_memory_peaks();

  // Names an object for validation messages (no-op without VK_EXT_debug_utils).
  void set_name(VkObjectType type, std::uint64_t handle, const std::string& name) const;

  // The kernel compiled for the description `key` (ComputePipeline): made by `make` on the
  // first request, then shared by every pipeline made with that description, and kept until
  // the context is released (before its device). `make` runs under the cache's lock.
  std::shared_ptr<const CompiledKernel> kernel(const std::string& key,
                                               const std::function<std::shared_ptr<const CompiledKernel>()>& make);

 private:
  void create_instance(bool validation);
  void pick_device(const std::string& override, const ContextOptions& options);
  void create_device(const ContextOptions& options);
  // Properties, limits, memory and queue of physical_device_ for queue_family_.
  void describe_device();
  void create_command_pool();
  // Ray queries are enabled on the device: features_.ray_query and the scratch alignment.
  void note_ray_queries();
  void release();

  std::shared_ptr<ValidationCounters> counters_ = std::make_shared<ValidationCounters>();
  bool validation_ = false;
  bool debug_utils_ = false;
  bool owns_device_ = true;  // false: a GivenDevice's instance and device
  bool external_memory_fd_ = false;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  DeviceInfo info_;
  VkPhysicalDeviceLimits limits_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  std::array<std::atomic<std::uint64_t>, VK_MAX_MEMORY_HEAPS> heap_in_use_{};
  std::array<std::atomic<std::uint64_t>, VK_MAX_MEMORY_HEAPS> heap_peak_{};
  std::uint64_t host_available_ = 0;  // bytes available to the process at creation (CPU devices)
  EnabledFeatures features_;
  PFN_vkSetDebugUtilsObjectNameEXT set_object_name_ = nullptr;
  std::mutex kernels_mutex_;
  std::map<std::string, std::shared_ptr<const CompiledKernel>> kernels_;
};

}  // namespace fovea::gpu
