#include "slot_writer.hpp"

#include <string>

#include "fovea/core/error.hpp"
#include "fovea/core/tonemap.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/shaders/layer_encode.h"

namespace fovea::layer {
namespace {

// The shader's curve is core/tonemap.hpp's, to float precision.
constexpr bool same_coefficient(float shader, double core) {
  const double d = double(shader) - core;
  return (d < 0 ? -d : d) <= 1e-7 * (core < 0 ? -core : core);
}
static_assert(same_coefficient(shaders::kAcesK0, core::AcesCoefficients::k0) &&
              same_coefficient(shaders::kAcesK1, core::AcesCoefficients::k1) && core::AcesCoefficients::k2 == 0.0 &&
              same_coefficient(shaders::kAcesK3, core::AcesCoefficients::k3) &&
              same_coefficient(shaders::kAcesK4, core::AcesCoefficients::k4) &&
              same_coefficient(shaders::kAcesK5, core::AcesCoefficients::k5));

gpu::Buffer import_slots(gpu::Context& ctx, const gpu::ExternalMemory& memory, VkDeviceSize bytes) {
  gpu::BufferDesc d;
  d.size = bytes;
  d.usage = gpu::BufferUsage::Storage;
  d.name = "layer traced-frame slots (the application's device memory)";
  d.imported = memory;
  return gpu::Buffer(ctx, d);
}

}  // namespace

SlotWriter::SlotWriter(gpu::Context& ctx, const gpu::ExternalMemory& memory, SlotLayout layout, int slots,
                       PixelFormat format)
    : ctx_(ctx), layout_(layout), slots_(slots), format_(format),
      memory_(import_slots(ctx, memory, layout.bytes(slots))),
      encode_(ctx, {"layer_encode.comp.spv", {gpu::declared_bindings("layer_encode.comp.spv")},
                    sizeof(shaders::EncodePush), {}}),
      sets_{gpu::DescriptorSet(ctx, encode_.set_layout(0)), gpu::DescriptorSet(ctx, encode_.set_layout(0))} {
  if (layout.width <= 0 || layout.height <= 0 || slots <= 0)
    throw core::InputError("SlotWriter: an empty slot layout");
}

void SlotWriter::write(const std::array<Eye, 2>& eyes, int slot) {
  if (slot < 0 || slot >= slots_) throw std::logic_error("SlotWriter::write: no slot " + std::to_string(slot));
  const std::uint64_t px = layout_.pixels();
  for (std::size_t e = 0; e < 2; ++e) {
    if (!eyes[e].screen || eyes[e].screen->size() < px * 16 || (eyes[e].depth && eyes[e].depth->size() < px * 4))
      throw std::logic_error("SlotWriter::write: an eye's buffers are smaller than the slots' raster");
    // The pipeline keeps its buffers: the sets are written at the first frame, and again only
    // for another buffer (the previous write waited for the device, so they are idle).
    if (bound_[e] == eyes[e].screen->handle()) continue;
    const gpu::BufferSlot bound[] = {{ENCODE_BINDING_SCREEN, eyes[e].screen}, {ENCODE_BINDING_SLOTS, &memory_}};
    sets_[e].bind_all(bound);
    bound_[e] = eyes[e].screen->handle();
  }
  ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
    // The slots come from the application's device (an external queue family) and go back to
    // it: acquired here, released below (ownership transfers of Vulkan's external memory).
    VkBufferMemoryBarrier own{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    own.dstAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    own.srcQueueFamilyIndex = VK_QUEUE_FAMILY_EXTERNAL;
    own.dstQueueFamilyIndex = ctx_.queue_family();
    own.buffer = memory_.handle();
    own.offset = layout_.colour_word(slot, 0) * 4;  // this slot only: the application reads others meanwhile
    own.size = layout_.bytes(1);
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 1, &own,
                         0, nullptr);
    for (int e = 0; e < 2; ++e) {
      shaders::EncodePush push{};
      push.pixels = std::uint32_t(px);
      push.first_word = std::uint32_t(layout_.colour_word(slot, e));
      push.srgb = format_.srgb ? 1u : 0u;
      push.bgra = format_.bgra ? 1u : 0u;
      encode_.run_linear(cmd, {&sets_[std::size_t(e)]}, push, push.pixels);
    }
    // The shader's writes are tracked over the whole bound buffer: the copies come after.
    gpu::barrier(cmd, gpu::access::compute_write, gpu::access::transfer_write);
    for (int e = 0; e < 2; ++e)
      if (eyes[std::size_t(e)].depth)
        gpu::copy_buffer(cmd, *eyes[std::size_t(e)].depth, memory_, px * 4, 0, layout_.depth_word(slot, e) * 4);
    // The writes made available and the slots released to the application's device, whose
    // composition pass acquires them before reading.
    own.srcAccessMask = own.dstAccessMask;
    own.dstAccessMask = 0;
    own.srcQueueFamilyIndex = ctx_.queue_family();
    own.dstQueueFamilyIndex = VK_QUEUE_FAMILY_EXTERNAL;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 1, &own, 0, nullptr);
  });
}

}  // namespace fovea::layer
