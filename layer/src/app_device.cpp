#include "app_device.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/memory_type.hpp"

namespace fovea::layer {
void app_check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed on the application's device: VkResult " + std::to_string(int(r)));
}

namespace {

VkImageMemoryBarrier image_barrier(VkImage image, std::uint32_t layer, VkImageLayout from, VkImageLayout to,
                                   VkAccessFlags src, VkAccessFlags dst,
                                   VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT) {
  return gpu::image_barrier_info(image, from, to, src, dst, {aspect, 0, 1, layer, 1});
}

// Bytes per texel of a depth aspect copied to a buffer (Vulkan's packing for buffer copies:
// D24 formats as 32-bit words with the depth in the low 24 bits), 0 for other formats.
std::uint32_t depth_texel_bytes(VkFormat f) {
  switch (f) {
    case VK_FORMAT_D16_UNORM: return 2;
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT: return 4;
    default: return 0;
  }
}

bool has_stencil(VkFormat f) { return f == VK_FORMAT_D24_UNORM_S8_UINT || f == VK_FORMAT_D32_SFLOAT_S8_UINT; }

float decode_depth(const std::uint8_t* p, VkFormat f) {
  switch (f) {
    case VK_FORMAT_D16_UNORM: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return float(v) / 65535.0f;
    }
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D24_UNORM_S8_UINT: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return float(double(v & 0xffffffu) / 16777215.0);
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return std::isfinite(v) ? v : 1.0f;  // a garbage texel counts as the far plane
    }
  }
}

}  // namespace

bool depth_format_supported(VkFormat f) { return depth_texel_bytes(f) != 0; }

// The application's device functions come from the Vulkan loader the layer links (through
// fovea_gpu), the same loader instance the application uses.
AppDevice::AppDevice(const VulkanBinding& vk) : device_(vk.device), queue_family_(vk.queue_family) {
  if (!vk.valid() || !vk.instance || !vk.physical_device)
    throw std::runtime_error("the session has no Vulkan graphics binding the layer can use");
  const auto gdpa = reinterpret_cast<PFN_vkGetDeviceProcAddr>(vkGetInstanceProcAddr(vk.instance, "vkGetDeviceProcAddr"));
  const auto props = reinterpret_cast<PFN_vkGetPhysicalDeviceMemoryProperties>(
      vkGetInstanceProcAddr(vk.instance, "vkGetPhysicalDeviceMemoryProperties"));
  if (!gdpa || !props) throw std::runtime_error("the application's VkInstance does not resolve vkGetDeviceProcAddr");
#define FOVEA_APP_VK_LOAD(name)                                                         \
  name##_ = reinterpret_cast<PFN_##name>(gdpa(device_, #name));                          \
  if (!name##_) throw std::runtime_error("the application's VkDevice does not resolve " #name);
  FOVEA_APP_VK(FOVEA_APP_VK_LOAD)
#undef FOVEA_APP_VK_LOAD
  props(vk.physical_device, &memory_);
  if (const auto device_props = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties>(
          vkGetInstanceProcAddr(vk.instance, "vkGetPhysicalDeviceProperties"))) {
    VkPhysicalDeviceProperties dp{};
    device_props(vk.physical_device, &dp);
    storage_alignment_ = std::max<VkDeviceSize>(dp.limits.minStorageBufferOffsetAlignment, 1);
  }
  if (const auto families = reinterpret_cast<PFN_vkGetPhysicalDeviceQueueFamilyProperties>(
          vkGetInstanceProcAddr(vk.instance, "vkGetPhysicalDeviceQueueFamilyProperties"))) {
    std::uint32_t n = 0;
    families(vk.physical_device, &n, nullptr);
    std::vector<VkQueueFamilyProperties> f(n);
    families(vk.physical_device, &n, f.data());
    family_has_compute_ = vk.queue_family < n && (f[vk.queue_family].queueFlags & VK_QUEUE_COMPUTE_BIT);
  }
  get_device_proc_ = gdpa;
  physical_device_ = vk.physical_device;
  no_shared_ = vk.added.no_external_memory;
  if (vk.external_memory_fd()) {
    // The instance is Vulkan 1.1 or later here (vulkan_enable.cpp raised it): the device's
    // UUID, for the layer's device to be made on the same physical device.
    const auto props2 = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties2>(
        vkGetInstanceProcAddr(vk.instance, "vkGetPhysicalDeviceProperties2"));
    external_buffer_properties_ = reinterpret_cast<PFN_vkGetPhysicalDeviceExternalBufferProperties>(
        vkGetInstanceProcAddr(vk.instance, "vkGetPhysicalDeviceExternalBufferProperties"));
    get_memory_fd_ = reinterpret_cast<PFN_vkGetMemoryFdKHR>(gdpa(device_, "vkGetMemoryFdKHR"));
    if (props2 && external_buffer_properties_ && get_memory_fd_) {
      VkPhysicalDeviceIDProperties id{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES};
      VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &id};
      props2(vk.physical_device, &p2);
      std::copy(std::begin(id.deviceUUID), std::end(id.deviceUUID), device_uuid_.begin());
      external_memory_ = true;
    } else {
      no_shared_ = "the application's Vulkan instance or device does not resolve the external-memory commands";
    }
  }
  vkGetDeviceQueue_(device_, vk.queue_family, vk.queue_index, &queue_handle_);
  // Bounded: a lost or hung device fails the session (the layer then passes it through)
  // instead of hanging the application's xrEndFrame.
  constexpr std::uint64_t kTimeoutNs = 10'000'000'000;
  queue_ = std::make_unique<gpu::ForeignQueue>(device_, gdpa, vk.queue_family, queue_handle_, kTimeoutNs,
                                                    "the application's device");
}

AppDevice::~AppDevice() {
  destroy_gpu();
  release(download_);
  release(upload_);
}

void AppDevice::release(Buffer& b) {
  if (b.mapped) vkUnmapMemory_(device_, b.memory);
  if (b.buffer) vkDestroyBuffer_(device_, b.buffer, nullptr);
  if (b.memory) vkFreeMemory_(device_, b.memory, nullptr);
  b = Buffer{};
}

void AppDevice::reserve(Buffer& b, VkDeviceSize size, VkBufferUsageFlags usage, bool host, bool prefer_device_local,
                        bool exported) {
  if (b.size >= size && b.exported == exported) return;
  constexpr auto kOpaqueFd = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  if (exported) {
    if (!external_memory_) throw std::runtime_error(no_shared_);
    VkPhysicalDeviceExternalBufferInfo query{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_BUFFER_INFO};
    query.usage = usage;
    query.handleType = kOpaqueFd;
    VkExternalBufferProperties can{VK_STRUCTURE_TYPE_EXTERNAL_BUFFER_PROPERTIES};
    external_buffer_properties_(physical_device_, &query, &can);
    const VkExternalMemoryFeatureFlags need =
        VK_EXTERNAL_MEMORY_FEATURE_EXPORTABLE_BIT | VK_EXTERNAL_MEMORY_FEATURE_IMPORTABLE_BIT;
    if ((can.externalMemoryProperties.externalMemoryFeatures & need) != need)
      throw std::runtime_error("the application's device cannot export and import storage buffers as opaque file "
                               "descriptors");
  }
  release(b);
  VkExternalMemoryBufferCreateInfo external{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO};
  external.handleTypes = kOpaqueFd;
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, exported ? &external : nullptr};
  bi.size = size;
  bi.usage = usage;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  app_check(vkCreateBuffer_(device_, &bi, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements_(device_, b.buffer, &req);
  // Host-coherent memory: no flush/invalidate around the copies. Exported memory: any type,
  // device-local where there is one.
  const VkMemoryPropertyFlags want = host       ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                     : exported ? 0
                                                : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  const VkMemoryPropertyFlags preferred = prefer_device_local || exported ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT : 0;
  const std::optional<std::uint32_t> type = gpu::find_memory_type(memory_, req.memoryTypeBits, want, preferred);
  if (!type) {
    release(b);
    throw std::runtime_error(std::string("the application's device has no ") +
                             (host ? "host-visible coherent" : "device-local") + " memory for the layer's buffers");
  }
  // Exported: dedicated, so that the importing device can repeat the allocation whatever the
  // driver requires.
  VkMemoryDedicatedAllocateInfo dedicated{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO};
  dedicated.buffer = b.buffer;
  VkExportMemoryAllocateInfo exporting{VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO, &dedicated};
  exporting.handleTypes = kOpaqueFd;
  VkMemoryAllocateInfo mi{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, exported ? &exporting : nullptr};
  mi.allocationSize = req.size;
  mi.memoryTypeIndex = *type;
  try {
    app_check(vkAllocateMemory_(device_, &mi, nullptr, &b.memory), "vkAllocateMemory");
    app_check(vkBindBufferMemory_(device_, b.buffer, b.memory, 0), "vkBindBufferMemory");
    if (host) app_check(vkMapMemory_(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  } catch (...) {
    release(b);
    throw;
  }
  b.size = size;
  b.exported = exported;
  b.memory_type = *type;
  b.allocation = req.size;
}

std::vector<Pixels8> AppDevice::read(const std::vector<Read>& reads) {
  VkDeviceSize total = 0;
  std::vector<VkDeviceSize> offsets;
  for (const Read& r : reads) {
    if (r.rect.extent.width <= 0 || r.rect.extent.height <= 0 || r.rect.offset.x < 0 || r.rect.offset.y < 0)
      throw std::runtime_error("a submitted imageRect is empty or negative");
    offsets.push_back(total);
    total += VkDeviceSize(r.rect.extent.width) * VkDeviceSize(r.rect.extent.height) * 4;
  }
  reserve(download_, total, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  ++host_readbacks_;
  queue_->run([&](VkCommandBuffer cb) {
    for (std::size_t i = 0; i < reads.size(); ++i) {
      const Read& r = reads[i];
      record_download(cb, {r.image, r.array_layer, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                           VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                           VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_ASPECT_COLOR_BIT, r.rect, offsets[i]},
                      download_.buffer);
    }
    record_host_read_barrier(cb);
  });
  std::vector<Pixels8> out;
  for (std::size_t i = 0; i < reads.size(); ++i) {
    Pixels8 p{reads[i].rect.extent.width, reads[i].rect.extent.height, {}};
    p.data.resize(std::size_t(p.width) * std::size_t(p.height) * 4);
    std::memcpy(p.data.data(), static_cast<const std::uint8_t*>(download_.mapped) + offsets[i], p.data.size());
    out.push_back(std::move(p));
  }
  return out;
}

void AppDevice::record_download(VkCommandBuffer cb, const Download& d, VkBuffer buffer) {
  // After the application's rendering (earlier submissions on this queue).
  auto to_src = image_barrier(d.image, d.array_layer, d.attachment_layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                              d.attachment_writes, VK_ACCESS_TRANSFER_READ_BIT, d.aspects);
  vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr,
                        1, &to_src);
  VkBufferImageCopy c{};
  c.bufferOffset = d.offset;
  c.imageSubresource = {d.copy_aspect, 0, d.array_layer, 1};
  c.imageOffset = {d.rect.offset.x, d.rect.offset.y, 0};
  c.imageExtent = {std::uint32_t(d.rect.extent.width), std::uint32_t(d.rect.extent.height), 1};
  vkCmdCopyImageToBuffer_(cb, d.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &c);
  auto back = image_barrier(d.image, d.array_layer, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, d.attachment_layout, 0, 0,
                            d.aspects);
  vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr,
                        1, &back);
}

void AppDevice::record_host_read_barrier(VkCommandBuffer cb) {
  VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0,
                        nullptr);
}

std::vector<std::vector<float>> AppDevice::read_depth(const std::vector<AppDepth>& reads) {
  VkDeviceSize total = 0;
  std::vector<VkDeviceSize> offsets;
  for (const AppDepth& r : reads) {
    if (r.rect.extent.width <= 0 || r.rect.extent.height <= 0 || r.rect.offset.x < 0 || r.rect.offset.y < 0)
      throw std::runtime_error("a submitted depth imageRect is empty or negative");
    if (!depth_format_supported(r.format))
      throw std::runtime_error("depth swapchain format " + std::to_string(int(r.format)) + " has no decoding");
    offsets.push_back(total);
    // Offsets stay multiples of 4 (buffer copies of depth aspects require it).
    total += (VkDeviceSize(r.rect.extent.width) * VkDeviceSize(r.rect.extent.height) * depth_texel_bytes(r.format) + 3) &
             ~VkDeviceSize(3);
  }
  reserve(download_, total, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  ++host_readbacks_;
  queue_->run([&](VkCommandBuffer cb) {
    for (std::size_t i = 0; i < reads.size(); ++i) record_download(cb, depth_download(reads[i], offsets[i]), download_.buffer);
    record_host_read_barrier(cb);
  });
  std::vector<std::vector<float>> out;
  for (std::size_t i = 0; i < reads.size(); ++i) {
    const AppDepth& r = reads[i];
    const std::size_t n = std::size_t(r.rect.extent.width) * std::size_t(r.rect.extent.height);
    const std::uint32_t bytes = depth_texel_bytes(r.format);
    const auto* src = static_cast<const std::uint8_t*>(download_.mapped) + offsets[i];
    std::vector<float> d(n);
    for (std::size_t k = 0; k < n; ++k) d[k] = decode_depth(src + k * bytes, r.format);
    out.push_back(std::move(d));
  }
  return out;
}

AppDevice::Download AppDevice::depth_download(const AppDepth& d, VkDeviceSize offset) {
  // Layout transitions cover every aspect of a combined depth/stencil image.
  const VkImageAspectFlags aspects = VK_IMAGE_ASPECT_DEPTH_BIT | (has_stencil(d.format) ? VK_IMAGE_ASPECT_STENCIL_BIT : 0);
  return {d.image, d.array_index, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, aspects,
          VK_IMAGE_ASPECT_DEPTH_BIT, d.rect, offset};
}

void AppDevice::write(const std::vector<VkImage>& images, const std::vector<const Pixels8*>& pixels) {
  VkDeviceSize total = 0;
  std::vector<VkDeviceSize> offsets;
  for (const Pixels8* p : pixels) {
    offsets.push_back(total);
    total += p->data.size();
  }
  reserve(upload_, total, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  for (std::size_t i = 0; i < pixels.size(); ++i)
    std::memcpy(static_cast<std::uint8_t*>(upload_.mapped) + offsets[i], pixels[i]->data.data(), pixels[i]->data.size());
  queue_->run([&](VkCommandBuffer cb) {
    for (std::size_t i = 0; i < images.size(); ++i)
      record_upload(cb, upload_.buffer, offsets[i], images[i], pixels[i]->width, pixels[i]->height);
  });
}

void AppDevice::record_upload(VkCommandBuffer cb, VkBuffer buffer, VkDeviceSize offset, VkImage image, int width,
                              int height) {
  // The whole image is overwritten: its old contents are discarded (after the runtime's
  // earlier reads of it on this queue).
  auto to_dst = image_barrier(image, 0, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                              VK_ACCESS_TRANSFER_WRITE_BIT);
  vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                        nullptr, 1, &to_dst);
  VkBufferImageCopy c{};
  c.bufferOffset = offset;
  c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  c.imageExtent = {std::uint32_t(width), std::uint32_t(height), 1};
  vkCmdCopyBufferToImage_(cb, buffer, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
  auto done = image_barrier(image, 0, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                            VK_ACCESS_TRANSFER_WRITE_BIT,
                            VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
                                VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
  vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                        nullptr, 1, &done);
}

}  // namespace fovea::layer
