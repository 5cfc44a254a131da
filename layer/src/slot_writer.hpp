#pragma once
// The traced frame's hand-over without the host: the GPU composition's traced-frame slots
// live in memory of the application's device (AppDevice), exported there and imported here
// into the layer's own device on the same physical GPU (VK_KHR_external_memory_fd). Each
// finished frame is encoded for the application's swapchain (shaders/layer_encode.comp) and
// its depths copied into a slot by the layer's device, then released to the external queue
// family; the application's composition pass acquires it. No pixel crosses the host.
#include <array>
#include <cstdint>

#include "composite.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"

namespace fovea::layer {

// A slot's layout, shared with AppDevice (4-byte words): per slot both eyes' colour, then
// both eyes' view distances, width × height words each.
struct SlotLayout {
  int width = 0, height = 0;
  std::uint64_t pixels() const { return std::uint64_t(width) * std::uint64_t(height); }
  std::uint64_t colour_word(int slot, int eye) const { return (std::uint64_t(slot) * 4 + std::uint64_t(eye)) * pixels(); }
  std::uint64_t depth_word(int slot, int eye) const { return (std::uint64_t(slot) * 4 + 2 + std::uint64_t(eye)) * pixels(); }
  std::uint64_t bytes(int slots) const { return std::uint64_t(slots) * 4 * pixels() * 4; }
};

class SlotWriter {
 public:
  // `ctx`: the layer's device, with external memory (ContextOptions::external_memory_fd);
  // `memory`: the slots' memory the application's device exported (its descriptor is taken).
  // Throws (core::InputError, gpu::VulkanError) when the import fails.
  SlotWriter(gpu::Context& ctx, const gpu::ExternalMemory& memory, SlotLayout layout, int slots, PixelFormat format);
  // One eye's finished frame on the layer's device: its displayed image (vec4 linear radiance
  // per pixel, row-major: FramePipeline::screen_buffer) and its view distances (float per
  // pixel: FramePipeline::depth_buffer; null: none, scene-only composition).
  struct Eye {
    const gpu::Buffer* screen = nullptr;
    const gpu::Buffer* depth = nullptr;
  };
  // Encodes both eyes into `slot`, releases the slots to the application's device and waits
  // until the device is done (the frame is published after: the application's device reads
  // the slot only then).
  void write(const std::array<Eye, 2>& eyes, int slot);

 private:
  gpu::Context& ctx_;
  SlotLayout layout_;
  int slots_;
  PixelFormat format_;
  gpu::Buffer memory_;  // the imported slots
  gpu::ComputePipeline encode_;
  std::array<gpu::DescriptorSet, 2> sets_;  // per eye: its displayed image, the slots
  std::array<VkBuffer, 2> bound_{};          // the displayed images the sets name
};

}  // namespace fovea::layer
