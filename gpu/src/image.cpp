#include "fovea/gpu/image.hpp"

#include <cstring>

#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/error.hpp"

namespace fovea::gpu {

std::uint32_t texel_bytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R8_UNORM:
      return 1;
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB:
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_R32_UINT:
    case VK_FORMAT_R16G16_SFLOAT:
      return 4;
    case VK_FORMAT_R32G32_SFLOAT:
    case VK_FORMAT_R32G32_UINT:
    case VK_FORMAT_R16G16B16A16_SFLOAT:
      return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
    case VK_FORMAT_R32G32B32A32_UINT:
      return 16;
    default:
      throw core::InputError("gpu::Image2D: VkFormat " + std::to_string(static_cast<int>(format)) +
                             " is not one of the formats Fovea supports (see texel_bytes)");
  }
}

Image2D::Image2D(Context& ctx, const ImageDesc& desc)
    : ctx_(&ctx), width_(desc.width), height_(desc.height), format_(desc.format) {
  const std::string what = "gpu::Image2D '" + desc.name + "'";
  if (desc.width == 0 || desc.height == 0) throw core::InputError(what + ": width and height must be > 0");
  if (desc.width > ctx.limits().maxImageDimension2D || desc.height > ctx.limits().maxImageDimension2D)
    throw core::InputError(what + ": " + std::to_string(desc.width) + "x" + std::to_string(desc.height) +
                           " exceeds the device limit " + std::to_string(ctx.limits().maxImageDimension2D));
  texel_bytes(desc.format);  // rejects unknown formats early

  VkImageUsageFlags usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  VkFormatFeatureFlags needed = VK_FORMAT_FEATURE_TRANSFER_SRC_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT;
  if (desc.storage) {
    usage |= VK_IMAGE_USAGE_STORAGE_BIT;
    needed |= VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT;
  }
  if (desc.sampled) {
    usage |= VK_IMAGE_USAGE_SAMPLED_BIT;
    needed |= VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT;
  }
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), desc.format, &fp);
  if ((fp.optimalTilingFeatures & needed) != needed)
    throw core::InputError(what + ": the device does not support VkFormat " +
                           std::to_string(static_cast<int>(desc.format)) + " for the requested usage" +
                           (desc.storage ? " (storage)" : "") + (desc.sampled ? " (sampled)" : ""));

  const VkDevice dev = ctx.device();
  VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = desc.format;
  ci.extent = {desc.width, desc.height, 1};
  ci.mipLevels = 1;
  ci.arrayLayers = 1;
  ci.samples = VK_SAMPLE_COUNT_1_BIT;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = usage;
  ci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage image = VK_NULL_HANDLE;
  check_fits(vkCreateImage(dev, &ci, nullptr, &image), "vkCreateImage",
             what + " (" + std::to_string(desc.width) + "x" + std::to_string(desc.height) + ")", 0, 0);
  image_ = {dev, image};

  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(dev, image, &req);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = ctx.memory_type(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  charge_ = ctx.charge_memory(what, req.size, ai.memoryTypeIndex);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  check_fits(vkAllocateMemory(dev, &ai, nullptr, &memory), "vkAllocateMemory", what, req.size,
             ctx.memory_type_heap_size(ai.memoryTypeIndex));
  memory_ = {dev, memory};
  check(vkBindImageMemory(dev, image, memory, 0), "vkBindImageMemory");

  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = desc.format;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  check(vkCreateImageView(dev, &vi, nullptr, &view), "vkCreateImageView");
  view_ = {dev, view};
  if (!desc.name.empty()) ctx.set_name(VK_OBJECT_TYPE_IMAGE, reinterpret_cast<std::uint64_t>(image), desc.name);

  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    image_barrier(cmd, image, VK_IMAGE_LAYOUT_UNDEFINED, kLayout, {}, access::all);
  });
}

void Image2D::upload_bytes(std::span<const std::byte> texels) {
  if (texels.size() != byte_size())
    throw std::invalid_argument("gpu::Image2D::upload: " + std::to_string(texels.size()) + " bytes given, " +
                                std::to_string(byte_size()) + " expected");
  Buffer staging(*ctx_, {texels.size(), BufferUsage::TransferSrc, Memory::HostVisible, "staging image upload"});
  std::memcpy(staging.mapped().data(), texels.data(), texels.size());
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { copy_buffer_to_image(cmd, staging.handle(), *this); });
}

void Image2D::download_bytes(std::span<std::byte> texels) const {
  if (texels.size() != byte_size())
    throw std::invalid_argument("gpu::Image2D::download: " + std::to_string(texels.size()) + " bytes given, " +
                                std::to_string(byte_size()) + " expected");
  Buffer staging(*ctx_, {texels.size(), BufferUsage::TransferDst, Memory::HostVisible, "staging image download"});
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { copy_image_to_buffer(cmd, *this, staging.handle()); });
  std::memcpy(texels.data(), staging.mapped().data(), texels.size());
}

namespace {
VkBufferImageCopy whole(const Image2D& image) {
  VkBufferImageCopy r{};
  r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  r.imageExtent = {image.width(), image.height(), 1};
  return r;
}
}  // namespace

void copy_buffer_to_image(VkCommandBuffer cmd, VkBuffer src, const Image2D& dst) {
  const VkBufferImageCopy r = whole(dst);
  vkCmdCopyBufferToImage(cmd, src, dst.handle(), Image2D::kLayout, 1, &r);
}

void copy_image_to_buffer(VkCommandBuffer cmd, const Image2D& src, VkBuffer dst) {
  const VkBufferImageCopy r = whole(src);
  vkCmdCopyImageToBuffer(cmd, src.handle(), Image2D::kLayout, dst, 1, &r);
}

Sampler::Sampler(Context& ctx, VkFilter filter, VkSamplerAddressMode address) {
  VkSamplerCreateInfo ci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  ci.magFilter = filter;
  ci.minFilter = filter;
  ci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  ci.addressModeU = ci.addressModeV = ci.addressModeW = address;
  ci.maxLod = 0.0f;
  VkSampler s = VK_NULL_HANDLE;
  check(vkCreateSampler(ctx.device(), &ci, nullptr, &s), "vkCreateSampler");
  sampler_ = {ctx.device(), s};
}

}  // namespace fovea::gpu
