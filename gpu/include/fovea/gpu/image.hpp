#pragma once
// 2-D images (one mip level, one layer, optimal tiling, own memory allocation). They
// live in VK_IMAGE_LAYOUT_GENERAL from creation on: storage access, sampling and copies
// all work there, so no layout tracking is needed between passes.
#include <cstddef>
#include <cstdint>
#include <ranges>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "fovea/gpu/handle.hpp"
#include "fovea/gpu/memory_charge.hpp"

namespace fovea::gpu {

class Context;

struct ImageDesc {
  std::uint32_t width = 0, height = 0;  // > 0
  VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT;
  bool storage = true;   // imageLoad/imageStore
  bool sampled = false;  // combined image sampler
  std::string name;      // shown in validation messages
};

// Bytes per texel of the formats Fovea uses; throws core::InputError for others.
std::uint32_t texel_bytes(VkFormat format);

class Image2D {
 public:
  static constexpr VkImageLayout kLayout = VK_IMAGE_LAYOUT_GENERAL;

  Image2D() = default;
  // Throws core::InputError when the device cannot use `format` as asked.
  Image2D(Context& ctx, const ImageDesc& desc);

  VkImage handle() const { return image_.get(); }
  VkImageView view() const { return view_.get(); }
  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }
  VkFormat format() const { return format_; }
  // Size of the tightly packed texels, rows top to bottom: what upload/download move.
  std::size_t byte_size() const { return std::size_t(width_) * height_ * texel_bytes(format_); }

  // Synchronous transfers of the whole image; the span must hold exactly byte_size() bytes.
  void upload_bytes(std::span<const std::byte> texels);
  void download_bytes(std::span<std::byte> texels) const;

  template <std::ranges::contiguous_range R>
  void upload(const R& texels) {
    static_assert(std::is_trivially_copyable_v<std::ranges::range_value_t<R>>);
    upload_bytes(std::as_bytes(std::span(std::ranges::data(texels), std::ranges::size(texels))));
  }
  // T is one texel (e.g. glm::vec4 for RGBA32F, std::uint32_t for R32_UINT or RGBA8).
  template <class T>
  std::vector<T> download() const {
    static_assert(std::is_trivially_copyable_v<T>);
    std::vector<T> v(byte_size() / sizeof(T));
    download_bytes(std::as_writable_bytes(std::span<T>(v)));
    return v;
  }

 private:
  Context* ctx_ = nullptr;
  std::uint32_t width_ = 0, height_ = 0;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  MemoryCharge charge_;                                 // returned after the memory is freed
  DeviceHandle<VkDeviceMemory, vkFreeMemory> memory_;  // declared first: destroyed last
  DeviceHandle<VkImage, vkDestroyImage> image_;
  DeviceHandle<VkImageView, vkDestroyImageView> view_;
};

// Records copies between a buffer holding tightly packed texels and the whole image.
void copy_buffer_to_image(VkCommandBuffer cmd, VkBuffer src, const Image2D& dst);
void copy_image_to_buffer(VkCommandBuffer cmd, const Image2D& src, VkBuffer dst);

// Sampler for combined image samplers: unnormalized = false, no mips, no anisotropy.
class Sampler {
 public:
  Sampler() = default;
  explicit Sampler(Context& ctx, VkFilter filter = VK_FILTER_LINEAR,
                   VkSamplerAddressMode address = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE);
  VkSampler handle() const { return sampler_.get(); }

 private:
  DeviceHandle<VkSampler, vkDestroySampler> sampler_;
};

}  // namespace fovea::gpu
