#pragma once
// Buffers: one VkBuffer with its own memory allocation (no sub-allocation; fine for
// the few hundred buffers Fovea uses). HostVisible buffers are persistently mapped and
// coherent; DeviceLocal buffers move data through a temporary staging buffer.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <ranges>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "fovea/gpu/handle.hpp"
#include "fovea/gpu/memory_charge.hpp"

namespace fovea::gpu {

class Context;

enum class BufferUsage : std::uint32_t {
  Storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
  Uniform = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT,
  TransferSrc = VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
  TransferDst = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
  // Ray queries (EnabledFeatures::ray_query): addressable memory, acceleration-structure
  // storage and build inputs.
  DeviceAddress = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
  AccelerationStructure = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR,
  BuildInput = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR,
  Indirect = VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,  // vkCmdDispatchIndirect's arguments
};
constexpr BufferUsage operator|(BufferUsage a, BufferUsage b) {
  return static_cast<BufferUsage>(static_cast<std::uint32_t>(a) | static_cast<std::uint32_t>(b));
}

enum class Memory {
  DeviceLocal,  // fastest for shaders; host access goes through staging copies
  HostVisible,  // mapped and coherent, host-cached where the device has such memory: readback
  // Mapped and coherent, device-local where the device has such memory (a discrete GPU's
  // BAR; any type of a CPU or integrated device): what the host writes for a frame and the
  // frame's shaders then read in many invocations or update by atomics. In host memory each
  // such read or atomic would cross the bus; reading it back is slow, so the host keeps its
  // own copy of what it wrote.
  Upload,
};

// The memory properties a kind requires and prefers (find_memory_type's arguments).
struct MemoryProperties {
  VkMemoryPropertyFlags required = 0, preferred = 0;
};
MemoryProperties memory_properties(Memory m);
// Where an Upload that took memory type `type` of a device-local heap goes when that heap is
// full (a BAR without resizable BAR holds 256 MiB for every user of the GPU): a mapped type
// of a heap in host memory, as HostVisible picks it; none when `type` is in host memory
// already or the device has no such heap (a CPU device's one heap).
std::optional<std::uint32_t> upload_fallback_type(const VkPhysicalDeviceMemoryProperties& memory,
                                                  std::uint32_t type_bits, std::uint32_t type);

// Memory another VkDevice of the same physical device allocated (dedicated to one buffer)
// and exported as an opaque file descriptor (VK_KHR_external_memory_fd): the allocation's
// size and memory type index, which an opaque import must repeat.
struct ExternalMemory {
  int fd = -1;
  VkDeviceSize allocation_size = 0;
  std::uint32_t memory_type = 0;
};

struct BufferDesc {
  VkDeviceSize size = 0;  // bytes, > 0
  BufferUsage usage = BufferUsage::Storage;
  Memory memory = Memory::DeviceLocal;
  std::string name;  // shown in validation messages
  // Also readable as a texel buffer (`textureBuffer` / `utextureBuffer`, texelFetch) of this
  // format (R32/R32G32/R32G32B32A32, UINT or SFLOAT): the buffer owns a view of itself that
  // DescriptorSet binds to Binding::TexelBuffer. lavapipe fetches a texel as one vector
  // gather, where a storage-buffer load whose address differs per invocation is a loop over
  // the SIMD lanes with a bounds test per component (docs/gpu.md, "Texel buffers").
  VkFormat texel_format = VK_FORMAT_UNDEFINED;
  // Bound to imported memory instead of its own (the Context enables external_memory_fd;
  // `memory` is ignored, the buffer is not mapped). The descriptor is the buffer's from then
  // on, closed also when the import fails.
  std::optional<ExternalMemory> imported;
};

class Buffer {
 public:
  Buffer() = default;
  // Transfer usages are always added so upload/download and copies work on any buffer.
  // Throws core::InputError for an unsupported texel_format or more texels than the
  // device's maxTexelBufferElements.
  Buffer(Context& ctx, const BufferDesc& desc);
  // Moves leave the source empty (no handle, size 0, not mapped).
  Buffer(Buffer&& o) noexcept;
  Buffer& operator=(Buffer&& o) noexcept;

  VkBuffer handle() const { return buffer_.get(); }
  VkDeviceSize size() const { return size_; }
  // The view of the whole buffer as texels of BufferDesc::texel_format (VK_NULL_HANDLE without).
  VkBufferView texel_view() const { return view_.get(); }
  // For buffers created with BufferUsage::DeviceAddress.
  VkDeviceAddress device_address() const;
  bool host_visible() const { return mapped_ != nullptr; }
  // The mapped bytes of a HostVisible buffer (empty for DeviceLocal). The GPU must be
  // done with them (submit_and_wait returned) before the host reads.
  std::span<std::byte> mapped() const { return {mapped_, mapped_ ? size_ : 0}; }

  // Synchronous transfers (a submit_and_wait each for DeviceLocal); throw
  // std::out_of_range when [offset, offset + bytes) exceeds the buffer.
  void upload_bytes(std::span<const std::byte> data, VkDeviceSize offset = 0);
  void download_bytes(std::span<std::byte> out, VkDeviceSize offset = 0) const;

  template <std::ranges::contiguous_range R>
  void upload(const R& data, VkDeviceSize offset = 0) {
    static_assert(std::is_trivially_copyable_v<std::ranges::range_value_t<R>>);
    upload_bytes(std::as_bytes(std::span(std::ranges::data(data), std::ranges::size(data))), offset);
  }
  template <class T>
  void download(std::span<T> out, VkDeviceSize offset = 0) const {
    static_assert(std::is_trivially_copyable_v<T>);
    download_bytes(std::as_writable_bytes(out), offset);
  }
  // The whole buffer as size() / sizeof(T) elements.
  template <class T>
  std::vector<T> download() const {
    std::vector<T> v(size_ / sizeof(T));
    download(std::span<T>(v));
    return v;
  }

 private:
  Context* ctx_ = nullptr;
  VkDeviceSize size_ = 0;
  std::byte* mapped_ = nullptr;
  MemoryCharge charge_;                                 // returned after the memory is freed
  DeviceHandle<VkDeviceMemory, vkFreeMemory> memory_;  // declared first: destroyed after the buffer
  DeviceHandle<VkBuffer, vkDestroyBuffer> buffer_;
  DeviceHandle<VkBufferView, vkDestroyBufferView> view_;  // declared last: destroyed before the buffer
};

// Bytes per texel of the formats BufferDesc::texel_format takes (R32, R32G32, R32G32B32A32,
// UINT or SFLOAT); 0 for any other.
VkDeviceSize texel_buffer_bytes(VkFormat format);

// Records a copy of `bytes` bytes between buffers (whole `src` when bytes == VK_WHOLE_SIZE).
void copy_buffer(VkCommandBuffer cmd, const Buffer& src, const Buffer& dst, VkDeviceSize bytes = VK_WHOLE_SIZE,
                 VkDeviceSize src_offset = 0, VkDeviceSize dst_offset = 0);
// Records a fill of the whole buffer with a repeated 32-bit word.
void fill_buffer(VkCommandBuffer cmd, const Buffer& buffer, std::uint32_t word);

}  // namespace fovea::gpu
