#include "fovea/gpu/buffer.hpp"

#include <unistd.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

#include "fovea/core/error.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/error.hpp"
#include "fovea/gpu/memory_type.hpp"

namespace fovea::gpu {
namespace {

void check_range(const Buffer& b, VkDeviceSize offset, std::size_t bytes, const char* what) {
  if (offset > b.size() || bytes > b.size() - offset)
    throw std::out_of_range(std::string(what) + ": " + std::to_string(bytes) + " bytes at offset " +
                            std::to_string(offset) + " exceed the buffer's " + std::to_string(b.size()) + " bytes");
}

std::string hex(std::uint32_t v) {
  char s[16];
  std::snprintf(s, sizeof s, "%x", v);
  return s;
}

}  // namespace

MemoryProperties memory_properties(Memory m) {
  // Mapped memory is also asked to be coherent, so no flushes are needed.
  constexpr VkMemoryPropertyFlags mapped = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  switch (m) {
    case Memory::HostVisible: return {mapped, VK_MEMORY_PROPERTY_HOST_CACHED_BIT};
    case Memory::Upload: return {mapped, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT};
    case Memory::DeviceLocal: break;
  }
  return {0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT};
}

std::optional<std::uint32_t> upload_fallback_type(const VkPhysicalDeviceMemoryProperties& memory,
                                                  std::uint32_t type_bits, std::uint32_t type) {
  const auto in_device_heap = [&](std::uint32_t i) {
    return (memory.memoryHeaps[memory.memoryTypes[i].heapIndex].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0;
  };
  if (type >= memory.memoryTypeCount || !in_device_heap(type)) return std::nullopt;
  std::uint32_t host_types = 0;
  for (std::uint32_t i = 0; i < memory.memoryTypeCount && i < 32; ++i)
    if (!in_device_heap(i)) host_types |= 1u << i;
  const MemoryProperties p = memory_properties(Memory::HostVisible);
  return find_memory_type(memory, type_bits & host_types, p.required, p.preferred);
}

VkDeviceSize texel_buffer_bytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R32_UINT: case VK_FORMAT_R32_SFLOAT: return 4;
    case VK_FORMAT_R32G32_UINT: case VK_FORMAT_R32G32_SFLOAT: return 8;
    case VK_FORMAT_R32G32B32A32_UINT: case VK_FORMAT_R32G32B32A32_SFLOAT: return 16;
    default: return 0;
  }
}

Buffer::Buffer(Context& ctx, const BufferDesc& desc) : ctx_(&ctx), size_(desc.size) {
  // An imported descriptor is closed on every failure before the import took it.
  struct Fd {
    int fd;
    ~Fd() {
      if (fd >= 0) close(fd);
    }
  } imported_fd{desc.imported ? desc.imported->fd : -1};
  if (desc.imported && !ctx.external_memory_fd())
    throw core::InputError("gpu::Buffer '" + desc.name + "': imported memory on a context without external memory");
  if (desc.size == 0) throw core::InputError("gpu::Buffer '" + desc.name + "': size must be > 0");
  const bool texels = desc.texel_format != VK_FORMAT_UNDEFINED;
  const VkDeviceSize texel = texel_buffer_bytes(desc.texel_format);
  if (texels && texel == 0)
    throw core::InputError("gpu::Buffer '" + desc.name + "': texel format " + std::to_string(desc.texel_format) +
                           " is not one of R32, R32G32, R32G32B32A32 (UINT or SFLOAT)");
  if (texels && desc.size / texel > ctx.limits().maxTexelBufferElements)
    throw core::InputError("gpu::Buffer '" + desc.name + "': " + std::to_string(desc.size / texel) +
                           " texels, more than this device's texel buffers hold (maxTexelBufferElements " +
                           std::to_string(ctx.limits().maxTexelBufferElements) + ")");
  const VkDevice dev = ctx.device();
  VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  ci.size = desc.size;
  ci.usage = static_cast<VkBufferUsageFlags>(desc.usage | BufferUsage::TransferSrc | BufferUsage::TransferDst);
  if (texels) ci.usage |= VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT;
  ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkExternalMemoryBufferCreateInfo external{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO};
  external.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  if (desc.imported) ci.pNext = &external;
  VkBuffer buffer = VK_NULL_HANDLE;
  const std::string what = "gpu::Buffer '" + desc.name + "'";
  check_fits(vkCreateBuffer(dev, &ci, nullptr, &buffer), "vkCreateBuffer", what, desc.size, 0);
  buffer_ = {dev, buffer};

  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(dev, buffer, &req);
  const bool host = desc.memory != Memory::DeviceLocal && !desc.imported;
  std::uint32_t type = 0;
  if (desc.imported) {
    type = desc.imported->memory_type;
    if (type >= 32 || (req.memoryTypeBits & (1u << type)) == 0 || desc.imported->allocation_size < req.size)
      throw core::InputError(what + ": the imported memory (type " + std::to_string(type) + ", " +
                             std::to_string(desc.imported->allocation_size) + " bytes) cannot hold it (" +
                             std::to_string(req.size) + " bytes, memory types 0x" + hex(req.memoryTypeBits) + ")");
  } else {
    const MemoryProperties p = memory_properties(desc.memory);
    type = ctx.memory_type(req.memoryTypeBits, p.required, p.preferred);
  }
  // An upload whose device-local memory is full goes to host memory: slower for its readers,
  // where failing would stop the frame. Taken before allocating when this context filled the
  // heap, and after a failed allocation when others did.
  std::optional<std::uint32_t> fallback;
  if (desc.memory == Memory::Upload && !desc.imported)
    fallback = upload_fallback_type(ctx.memory_types(), req.memoryTypeBits, type);
  if (fallback && ctx.memory_in_use(type) + req.size > ctx.memory_limit(type))
    type = *std::exchange(fallback, std::nullopt);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = desc.imported ? desc.imported->allocation_size : req.size;
  ai.memoryTypeIndex = type;
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  if ((ci.usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) != 0) ai.pNext = &flags;
  // An opaque import repeats the export's dedicated allocation.
  VkMemoryDedicatedAllocateInfo dedicated{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO};
  dedicated.buffer = buffer;
  VkImportMemoryFdInfoKHR import{VK_STRUCTURE_TYPE_IMPORT_MEMORY_FD_INFO_KHR, &dedicated};
  import.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  import.fd = imported_fd.fd;
  if (desc.imported) {
    dedicated.pNext = ai.pNext;
    ai.pNext = &import;
  }
  charge_ = ctx.charge_memory(what, req.size, type);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkResult allocated = vkAllocateMemory(dev, &ai, nullptr, &memory);
  if (allocated == VK_ERROR_OUT_OF_DEVICE_MEMORY && fallback) {
    charge_ = {};
    type = ai.memoryTypeIndex = *fallback;
    charge_ = ctx.charge_memory(what, req.size, type);
    allocated = vkAllocateMemory(dev, &ai, nullptr, &memory);
  }
  check_fits(allocated, "vkAllocateMemory", what, req.size, ctx.memory_type_heap_size(type));
  imported_fd.fd = -1;  // the memory owns it now
  memory_ = {dev, memory};
  check(vkBindBufferMemory(dev, buffer, memory, 0), "vkBindBufferMemory");
  if (host) {
    void* p = nullptr;
    check(vkMapMemory(dev, memory, 0, VK_WHOLE_SIZE, 0, &p), "vkMapMemory");
    mapped_ = static_cast<std::byte*>(p);
  }
  if (texels) {
    VkBufferViewCreateInfo vi{VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO};
    vi.buffer = buffer;
    vi.format = desc.texel_format;
    vi.range = desc.size / texel * texel;
    VkBufferView view = VK_NULL_HANDLE;
    check(vkCreateBufferView(dev, &vi, nullptr, &view), "vkCreateBufferView");
    view_ = {dev, view};
  }
  if (!desc.name.empty()) ctx.set_name(VK_OBJECT_TYPE_BUFFER, reinterpret_cast<std::uint64_t>(buffer), desc.name);
}

Buffer::Buffer(Buffer&& o) noexcept
    : ctx_(std::exchange(o.ctx_, nullptr)),
      size_(std::exchange(o.size_, 0)),
      mapped_(std::exchange(o.mapped_, nullptr)),
      charge_(std::move(o.charge_)),
      memory_(std::move(o.memory_)),
      buffer_(std::move(o.buffer_)),
      view_(std::move(o.view_)) {}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    view_ = std::move(o.view_);      // the view goes before its buffer,
    buffer_ = std::move(o.buffer_);  // the buffer before the memory it is bound to
    memory_ = std::move(o.memory_);
    charge_ = std::move(o.charge_);
    ctx_ = std::exchange(o.ctx_, nullptr);
    size_ = std::exchange(o.size_, 0);
    mapped_ = std::exchange(o.mapped_, nullptr);
  }
  return *this;
}

VkDeviceAddress Buffer::device_address() const {
  VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  info.buffer = buffer_.get();
  return vkGetBufferDeviceAddress(ctx_->device(), &info);
}

void Buffer::upload_bytes(std::span<const std::byte> data, VkDeviceSize offset) {
  check_range(*this, offset, data.size(), "gpu::Buffer::upload");
  if (data.empty()) return;
  if (mapped_ != nullptr) {
    std::memcpy(mapped_ + offset, data.data(), data.size());
    return;
  }
  Buffer staging(*ctx_, {data.size(), BufferUsage::TransferSrc, Memory::HostVisible, "staging upload"});
  std::memcpy(staging.mapped_, data.data(), data.size());
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { copy_buffer(cmd, staging, *this, data.size(), 0, offset); });
}

void Buffer::download_bytes(std::span<std::byte> out, VkDeviceSize offset) const {
  check_range(*this, offset, out.size(), "gpu::Buffer::download");
  if (out.empty()) return;
  if (mapped_ != nullptr) {
    std::memcpy(out.data(), mapped_ + offset, out.size());
    return;
  }
  Buffer staging(*ctx_, {out.size(), BufferUsage::TransferDst, Memory::HostVisible, "staging download"});
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { copy_buffer(cmd, *this, staging, out.size(), offset, 0); });
  std::memcpy(out.data(), staging.mapped_, out.size());
}

void copy_buffer(VkCommandBuffer cmd, const Buffer& src, const Buffer& dst, VkDeviceSize bytes,
                 VkDeviceSize src_offset, VkDeviceSize dst_offset) {
  VkBufferCopy region{src_offset, dst_offset, bytes == VK_WHOLE_SIZE ? src.size() - src_offset : bytes};
  vkCmdCopyBuffer(cmd, src.handle(), dst.handle(), 1, &region);
}

void fill_buffer(VkCommandBuffer cmd, const Buffer& buffer, std::uint32_t word) {
  vkCmdFillBuffer(cmd, buffer.handle(), 0, VK_WHOLE_SIZE, word);
}

}  // namespace fovea::gpu
