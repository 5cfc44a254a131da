// The layer's composition as a compute pass on the application's device (AppDevice::composite_gpu):
// xr_layer_composite.comp runs resample() and composite() of composite.cpp on packed 8-bit
// pixels in device buffers. The render thread writes each traced frame into a slot of a
// persistently mapped host-visible buffer of this device, which the pass reads directly (no
// copy of a frame on the application's thread). Per application frame one submission on the
// session queue copies the application's projection views into a buffer (the TRANSFER_SRC
// usage the layer requests), finds AppOnTop's background on the border, composites both eyes
// and copies the results into the layer's swapchain images; its command buffer was recorded at
// the first frame with the same images, so xrEndFrame writes the frame's parameters and
// submits. Nothing of the application's images reaches the host.
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "app_device.hpp"
#include "slot_writer.hpp"
#include "fovea/core/clock.hpp"
#include "fovea/core/image.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/shaders/embedded.hpp"
#include "fovea/shaders/layer_composite.h"

namespace fovea::layer {

namespace {

constexpr std::uint32_t kBindings = LAYER_BINDING_COUNT;
// The pipelines of the two passes, in Gpu::program.
constexpr std::size_t kBorderPipeline = 0, kCompositePipeline = 1;
// The composite pass's workgroup.
constexpr std::uint32_t kGroupX = 32, kGroupY = 8;
// A lost or hung device fails the session instead of hanging the application's call.
constexpr std::uint64_t kTimeoutNs = 10'000'000'000;

struct Push {
  std::uint32_t eye;
};

void set_tan(float out[4], const core::View& v) {
  out[0] = float(v.tan_left());
  out[1] = float(v.tan_right());
  out[2] = float(v.tan_up());
  out[3] = float(v.tan_down());
}

// How a buffer copy packs the depth aspect of `f` (kLayerDepth*); depth_format_supported() formats only.
std::uint32_t depth_packing(VkFormat f) {
  switch (f) {
    case VK_FORMAT_D16_UNORM: return shaders::kLayerDepthD16;
    case VK_FORMAT_X8_D24_UNORM_PACK32:
    case VK_FORMAT_D24_UNORM_S8_UINT: return shaders::kLayerDepthD24;
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT: return shaders::kLayerDepthD32F;
    default: break;
  }
  throw std::runtime_error("depth swapchain format " + std::to_string(int(f)) + " has no decoding");
}

float inverse_plane(float z) { return std::isinf(z) ? 0.0f : float(1.0 / double(z)); }

std::array<std::int32_t, 4> rect_key(const XrRect2Di& r) { return {r.offset.x, r.offset.y, r.extent.width, r.extent.height}; }
XrRect2Di rect_of(const std::array<std::int32_t, 4>& k) { return {{k[0], k[1]}, {k[2], k[3]}}; }

VkMemoryBarrier memory_barrier(VkAccessFlags src, VkAccessFlags dst) {
  VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  b.srcAccessMask = src;
  b.dstAccessMask = dst;
  return b;
}

// Where a pass's inputs and outputs lie in the composition buffers (pixels; depth: bytes),
// from what the pass was recorded for.
struct PassLayout {
  std::array<std::uint32_t, 2> app_offset{}, depth_offset{}, out_offset{};
  VkDeviceSize app_bytes = 0, depth_bytes = 0;
};

PassLayout layout_of(const CompositionPassKey& k) {
  PassLayout l;
  std::uint32_t app_px = 0, out_px = 0;
  for (std::size_t e = 0; e < 2; ++e) {
    l.app_offset[e] = app_px;
    l.out_offset[e] = out_px;
    if (k.with_app) app_px += std::uint32_t(k.app_rect[e][2] * k.app_rect[e][3]);
    out_px += std::uint32_t(k.out_w[e] * k.out_h[e]);
    l.depth_offset[e] = std::uint32_t(l.depth_bytes);
    if (k.by_depth)  // offsets stay multiples of 4 (buffer copies of depth aspects require it)
      l.depth_bytes += (VkDeviceSize(k.depth_rect[e][2]) * VkDeviceSize(k.depth_rect[e][3]) *
                            (depth_packing(k.depth_format[e]) == shaders::kLayerDepthD16 ? 2 : 4) + 3) &
                       ~VkDeviceSize(3);
  }
  l.app_bytes = VkDeviceSize(app_px) * 4;
  return l;
}

}  // namespace

bool CompositionPassKey::names(VkImage image) const {
  for (std::size_t e = 0; e < 2; ++e)
    if (target[e] == image || (with_app && app[e] == image) || (by_depth && depth[e] == image)) return true;
  return false;
}

void AppDevice::enable_gpu_composition(int traced_width, int traced_height, int slots) {
  if (gpu_) return;
  if (!family_has_compute_)
    throw std::runtime_error("the session's queue family " + std::to_string(queue_family_) + " has no compute");
  if (traced_width <= 0 || traced_height <= 0)
    throw std::runtime_error("enable_gpu_composition: an empty traced raster");
  gpu_ = std::make_unique<Gpu>();
  Gpu& g = *gpu_;
  try {
    // The parameters with a dynamic offset: each pass reads its own block. One pipeline per
    // pass (specialisation constants 0: the pass, 1 and 2: the workgroup size).
    gpu::ForeignPipelineDesc desc{"xr_layer_composite.comp.spv", {}, sizeof(Push), {}};
    desc.bindings.assign(kBindings, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
    desc.bindings[LAYER_BINDING_PARAMS] = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC;
    desc.specializations.resize(2);
    desc.specializations[kBorderPipeline] = {shaders::kLayerPassBorder, shaders::kLayerBorderGroup, 1u};
    desc.specializations[kCompositePipeline] = {shaders::kLayerPassComposite, kGroupX, kGroupY};
    g.program = gpu::create_foreign_pipelines(device_, get_device_proc_, desc);
    const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC, 1},
                                           {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBindings - 1}};
    VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pi.maxSets = 1;
    pi.poolSizeCount = 2;
    pi.pPoolSizes = sizes;
    app_check(vkCreateDescriptorPool_(device_, &pi, nullptr, &g.pool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = g.pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &g.program.set_layout;
    app_check(vkAllocateDescriptorSets_(device_, &ai, &g.set), "vkAllocateDescriptorSets");
    // Command buffers re-recorded in place when their images change.
    VkCommandPoolCreateInfo cpi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    cpi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cpi.queueFamilyIndex = queue_family_;
    app_check(vkCreateCommandPool_(device_, &cpi, nullptr, &g.commands), "vkCreateCommandPool");
    std::array<VkCommandBuffer, kPasses> cbs{};
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = g.commands;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = std::uint32_t(kPasses);
    app_check(vkAllocateCommandBuffers_(device_, &cai, cbs.data()), "vkAllocateCommandBuffers");
    for (std::size_t i = 0; i < kPasses; ++i) {
      g.passes[i].cb = cbs[i];
      const VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
      app_check(vkCreateFence_(device_, &fi, nullptr, &g.passes[i].fence), "vkCreateFence");
    }
    constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    g.params_stride = (sizeof(shaders::LayerCompositeParams) + storage_alignment_ - 1) / storage_alignment_ * storage_alignment_;
    reserve(g.params, g.params_stride * kPasses, storage);
    g.traced_w = traced_width;
    g.traced_h = traced_height;
    g.slots = std::make_shared<SlotPool>(slots);
    // Per slot both eyes' colour, then both eyes' view distances: 4 bytes per pixel each
    // (SlotLayout). Written by the layer's device where it can import them, else by the host.
    const VkDeviceSize traced_bytes = SlotLayout{traced_width, traced_height}.bytes(slots);
    if (external_memory_) {
      try {
        reserve(g.traced, traced_bytes, storage, false, true, true);
      } catch (const std::exception& e) {
        no_shared_ = e.what();
      }
    }
    if (!g.traced.exported) reserve(g.traced, traced_bytes, storage, true, true);
    reserve(g.out, 2 * VkDeviceSize(traced_width) * VkDeviceSize(traced_height) * 4,
            storage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false);
    reserve(g.background, 2 * sizeof(std::uint32_t), storage, false);
  } catch (...) {
    destroy_gpu();
    throw;
  }
}

std::shared_ptr<SlotPool> AppDevice::traced_slots() const { return gpu_ ? gpu_->slots : nullptr; }

std::optional<AppDevice::SharedSlots> AppDevice::shared_slots() const {
  if (!gpu_ || !gpu_->traced.exported) return std::nullopt;
  VkMemoryGetFdInfoKHR gi{VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR};
  gi.memory = gpu_->traced.memory;
  gi.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  int fd = -1;
  app_check(get_memory_fd_(device_, &gi, &fd), "vkGetMemoryFdKHR");
  return SharedSlots{{fd, gpu_->traced.allocation, gpu_->traced.memory_type}, device_uuid_};
}

std::uint8_t* AppDevice::slot_colour(int slot, int eye) const {
  if (!gpu_ || !gpu_->traced.mapped) throw std::logic_error("slot_colour: the slots are not host-visible");
  if (slot < 0 || slot >= gpu_->slots->slots() || eye < 0 || eye > 1)
    throw std::logic_error("slot_colour: no such slot");
  const SlotLayout l{gpu_->traced_w, gpu_->traced_h};
  return static_cast<std::uint8_t*>(gpu_->traced.mapped) + l.colour_word(slot, eye) * 4;
}

float* AppDevice::slot_depth(int slot, int eye) const {
  if (!gpu_ || !gpu_->traced.mapped) throw std::logic_error("slot_depth: the slots are not host-visible");
  if (slot < 0 || slot >= gpu_->slots->slots() || eye < 0 || eye > 1)
    throw std::logic_error("slot_depth: no such slot");
  const SlotLayout l{gpu_->traced_w, gpu_->traced_h};
  return reinterpret_cast<float*>(static_cast<std::uint8_t*>(gpu_->traced.mapped) + l.depth_word(slot, eye) * 4);
}

AppDevice::GpuStats AppDevice::gpu_stats() const {
  std::lock_guard lock(pass_mutex_);
  return gpu_ ? gpu_->counters : GpuStats{};
}

void AppDevice::release_retired(bool wait) {
  Gpu& g = *gpu_;
  g.retiring |= g.slots->take_retired();
  for (int s = 0; s < g.slots->slots(); ++s) {
    if (!(g.retiring & (1u << s))) continue;
    bool read = false;
    for (Pass& p : g.passes) {
      if (p.slot != s) continue;
      if (wait) wait_pass(p, g.counters.reuse_waits);
      read = read || pass_pending(p);
    }
    if (read) continue;
    g.retiring &= ~(1u << s);
    g.slots->release(s);
  }
}

void AppDevice::release_retired_slots() {
  std::lock_guard lock(pass_mutex_);
  if (gpu_) release_retired(true);
}

bool AppDevice::pass_pending(Pass& p) {
  if (!p.pending) return false;
  const VkResult r = vkGetFenceStatus_(device_, p.fence);
  if (r == VK_NOT_READY) return true;
  app_check(r, "vkGetFenceStatus");
  p.pending = false;
  return false;
}

void AppDevice::wait_pass(Pass& p, std::int64_t& waits) {
  if (!pass_pending(p)) return;
  ++waits;
  const VkResult r = vkWaitForFences_(device_, 1, &p.fence, VK_TRUE, kTimeoutNs);
  if (r == VK_TIMEOUT)
    throw std::runtime_error("a composition pass did not finish on the application's device in " +
                             std::to_string(kTimeoutNs / 1'000'000) + " ms");
  app_check(r, "vkWaitForFences");
  p.pending = false;
}

void AppDevice::finish() {
  std::lock_guard lock(pass_mutex_);
  if (gpu_)
    for (Pass& p : gpu_->passes) wait_pass(p, gpu_->counters.reuse_waits);
}

int AppDevice::finish_image(VkImage image) {
  std::lock_guard lock(pass_mutex_);
  int waited = 0;
  if (gpu_)
    for (Pass& p : gpu_->passes)
      if (p.pending && p.key.names(image)) {
        wait_pass(p, gpu_->counters.acquire_waits);
        ++waited;
      }
  return waited;
}

void AppDevice::forget_images(const std::vector<VkImage>& images) {
  std::lock_guard lock(pass_mutex_);
  if (!gpu_) return;
  for (Pass& p : gpu_->passes)
    if (p.recorded && std::any_of(images.begin(), images.end(), [&](VkImage i) { return p.key.names(i); })) {
      wait_pass(p, gpu_->counters.reuse_waits);
      p.recorded = false;
    }
}

void AppDevice::destroy_gpu() {
  if (!gpu_) return;
  Gpu& g = *gpu_;
  for (Pass& p : g.passes) {
    // Its command buffer and the buffers below must not be in use when they go; a failed
    // wait leaves nothing better to do.
    if (p.pending) vkWaitForFences_(device_, 1, &p.fence, VK_TRUE, kTimeoutNs);
    if (p.fence) vkDestroyFence_(device_, p.fence, nullptr);
  }
  if (g.commands) vkDestroyCommandPool_(device_, g.commands, nullptr);  // frees the command buffers
  for (Buffer* b : {&g.params, &g.traced, &g.app, &g.app_depth, &g.out, &g.background}) release(*b);
  if (g.pool) vkDestroyDescriptorPool_(device_, g.pool, nullptr);
  gpu::destroy_foreign_pipelines(device_, get_device_proc_, g.program);
  gpu_.reset();
}

void AppDevice::reserve_gpu_buffers(VkDeviceSize app_bytes, VkDeviceSize depth_bytes) {
  Gpu& g = *gpu_;
  app_bytes = std::max<VkDeviceSize>(app_bytes, 4);
  depth_bytes = std::max<VkDeviceSize>(depth_bytes, 4);
  if (g.set_written && g.app.size >= app_bytes && g.app_depth.size >= depth_bytes) return;
  // A buffer grows (the first frame, or larger application rects): nothing may use the old
  // one, and the set, and so every recorded pass, names the new one.
  for (Pass& p : g.passes) {
    wait_pass(p, g.counters.reuse_waits);
    p.recorded = false;
  }
  constexpr VkBufferUsageFlags dst = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  reserve(g.app, app_bytes, dst, false);
  reserve(g.app_depth, depth_bytes, dst, false);
  const std::pair<std::uint32_t, const Buffer*> bound[kBindings] = {
      {LAYER_BINDING_PARAMS, &g.params}, {LAYER_BINDING_TRACED, &g.traced},
      {LAYER_BINDING_APP, &g.app},       {LAYER_BINDING_OUT, &g.out},
      {LAYER_BINDING_BACKGROUND, &g.background}, {LAYER_BINDING_APP_DEPTH, &g.app_depth}};
  VkDescriptorBufferInfo infos[kBindings];
  VkWriteDescriptorSet writes[kBindings];
  for (std::uint32_t i = 0; i < kBindings; ++i) {
    const auto [binding, buffer] = bound[i];
    const bool params = binding == LAYER_BINDING_PARAMS;
    infos[i] = {buffer->buffer, 0, params ? VkDeviceSize(sizeof(shaders::LayerCompositeParams)) : VK_WHOLE_SIZE};
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = g.set;
    writes[i].dstBinding = binding;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = params ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  vkUpdateDescriptorSets_(device_, kBindings, writes, 0, nullptr);
  ++g.counters.descriptor_updates;
  g.set_written = true;
}

void AppDevice::record_pass(Pass& pass, std::size_t index) {
  Gpu& g = *gpu_;
  const PassKey& k = pass.key;
  const PassLayout l = layout_of(k);
  const VkCommandBuffer cb = pass.cb;
  const VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  app_check(vkBeginCommandBuffer_(cb, &bi), "vkBeginCommandBuffer");
  // The copies of the application's images end with a barrier whose second scope spans every
  // later submission on the queue, so the application's next rendering into them waits for
  // the copies on the device, and the runtime waits for the session queue's work before it
  // reads the layer's images (as for any application's).
  if (k.with_app)
    for (std::size_t e = 0; e < 2; ++e)
      record_download(cb,
                      {k.app[e], k.app_layer[e], VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                       VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_ASPECT_COLOR_BIT, rect_of(k.app_rect[e]),
                       VkDeviceSize(l.app_offset[e]) * 4},
                      g.app.buffer);
  if (k.by_depth)
    for (std::size_t e = 0; e < 2; ++e)
      record_download(cb,
                      depth_download({k.depth[e], k.depth_format[e], rect_of(k.depth_rect[e]), k.depth_layer[e], {}},
                                     VkDeviceSize(l.depth_offset[e])),
                      g.app_depth.buffer);
  // After the copies above; the host's writes (the parameters, a host-written traced slot)
  // are visible through the submission. Slots the layer's device wrote (exported memory) are
  // acquired from it (an external queue family) and released back after the pass.
  const VkMemoryBarrier to_compute = memory_barrier(VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT);
  VkBufferMemoryBarrier slots{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  slots.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  slots.srcQueueFamilyIndex = VK_QUEUE_FAMILY_EXTERNAL;
  slots.dstQueueFamilyIndex = queue_family_;
  slots.buffer = g.traced.buffer;
  slots.size = VK_WHOLE_SIZE;
  const std::uint32_t shared = g.traced.exported ? 1u : 0u;
  vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &to_compute, shared, &slots, 0, nullptr);
  const std::uint32_t params_offset = std::uint32_t(g.params_stride * index);
  vkCmdBindDescriptorSets_(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.program.layout, 0, 1, &g.set, 1, &params_offset);
  if (k.border) {
    vkCmdBindPipeline_(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.program.pipelines[kBorderPipeline]);
    for (std::uint32_t e = 0; e < 2; ++e) {
      const Push push{e};
      vkCmdPushConstants_(cb, g.program.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
      vkCmdDispatch_(cb, 1, 1, 1);
    }
    const VkMemoryBarrier border = memory_barrier(VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT);
    vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &border,
                          0, nullptr, 0, nullptr);
  }
  vkCmdBindPipeline_(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.program.pipelines[kCompositePipeline]);
  for (std::uint32_t e = 0; e < 2; ++e) {
    const Push push{e};
    vkCmdPushConstants_(cb, g.program.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatch_(cb, (std::uint32_t(k.out_w[e]) + kGroupX - 1) / kGroupX,
                  (std::uint32_t(k.out_h[e]) + kGroupY * shaders::kLayerRowsPerInvocation - 1) /
                      (kGroupY * shaders::kLayerRowsPerInvocation), 1);
  }
  const VkMemoryBarrier to_transfer = memory_barrier(VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  slots.srcAccessMask = 0;  // reads only: nothing to make available
  slots.dstAccessMask = 0;
  slots.srcQueueFamilyIndex = queue_family_;
  slots.dstQueueFamilyIndex = VK_QUEUE_FAMILY_EXTERNAL;
  vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &to_transfer,
                        shared, &slots, 0, nullptr);
  for (std::size_t e = 0; e < 2; ++e)
    record_upload(cb, g.out.buffer, VkDeviceSize(l.out_offset[e]) * 4, k.target[e], k.out_w[e], k.out_h[e]);
  app_check(vkEndCommandBuffer_(cb), "vkEndCommandBuffer");
  pass.recorded = true;
  ++g.counters.recordings;
}

void AppDevice::composite_gpu(int slot, const std::array<GpuEye, 2>& eyes, const CompositionRule& rule) {
  if (!gpu_) throw std::logic_error("composite_gpu: GPU composition was not enabled");
  Gpu& g = *gpu_;
  std::lock_guard lock(pass_mutex_);
  if (slot < 0 || slot >= g.slots->slots()) throw std::logic_error("composite_gpu: no such traced slot");
  release_retired(false);

  const bool with_app = rule.mode != Composite::SceneOnly;
  // By depth when both eyes bring the application's depth image (the slot holds the traced depths).
  const bool by_depth = with_app && eyes[0].depth && eyes[1].depth;
  PassKey key;
  key.with_app = with_app;
  key.by_depth = by_depth;
  key.border = with_app && !by_depth && rule.mode == Composite::AppOnTop && !rule.background;
  shaders::LayerCompositeParams p{};
  const SlotLayout layout{g.traced_w, g.traced_h};
  for (std::size_t e = 0; e < 2; ++e) {
    const EyeComposition& c = eyes[e].composition;
    if (c.traced_view.width() != g.traced_w || c.traced_view.height() != g.traced_h ||
        c.out_view.width() != g.traced_w || c.out_view.height() != g.traced_h)
      throw std::logic_error("composite_gpu: the views differ from the traced slots' raster");
    const XrRect2Di& r = eyes[e].app.rect;
    if (with_app && (r.extent.width <= 0 || r.extent.height <= 0 || r.offset.x < 0 || r.offset.y < 0))
      throw std::runtime_error("a submitted imageRect is empty or negative");
    key.target[e] = eyes[e].target;
    key.out_w[e] = c.out_view.width();
    key.out_h[e] = c.out_view.height();
    if (with_app) {
      key.app[e] = eyes[e].app.image;
      key.app_rect[e] = rect_key(r);
      key.app_layer[e] = eyes[e].app.array_layer;
    }
    if (by_depth) {
      const AppDepth& d = *eyes[e].depth;
      if (d.rect.extent.width != r.extent.width || d.rect.extent.height != r.extent.height || d.rect.offset.x < 0 ||
          d.rect.offset.y < 0)
        throw std::runtime_error("a submitted depth imageRect differs in size from its colour imageRect");
      depth_packing(d.format);  // throws for a format without a decoding
      key.depth[e] = d.image;
      key.depth_rect[e] = rect_key(d.rect);
      key.depth_layer[e] = d.array_index;
      key.depth_format[e] = d.format;
    }
  }
  const PassLayout l = layout_of(key);
  for (std::size_t e = 0; e < 2; ++e) {
    const EyeComposition& c = eyes[e].composition;
    shaders::LayerCompositeEye& pe = p.eye[e];
    set_tan(pe.out_tan, c.out_view);
    set_tan(pe.traced_tan, c.traced_view);
    const glm::dmat3 r = glm::mat3_cast(c.to_traced);
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col) pe.to_traced[row * 3 + col] = float(r[col][row]);  // glm: column-major
    pe.out_w = key.out_w[e];
    pe.out_h = key.out_h[e];
    pe.traced_w = g.traced_w;
    pe.traced_h = g.traced_h;
    pe.app_w = key.app_rect[e][2];
    pe.app_h = key.app_rect[e][3];
    // The slot: both eyes' colour, then both eyes' distances (slot_colour, slot_depth).
    pe.traced_offset = std::uint32_t(layout.colour_word(slot, int(e)));
    pe.traced_depth_offset = std::uint32_t(layout.depth_word(slot, int(e)));
    pe.app_offset = l.app_offset[e];
    pe.out_offset = l.out_offset[e];
    // resample()'s shortcut, taken alike: a copy without resampling.
    pe.traced_identity = resample_copies(c.traced_view, pe.traced_w, pe.traced_h, c.out_view, c.to_traced);
    pe.app_identity = with_app && resample_copies(c.app_view, pe.app_w, pe.app_h, c.out_view);
    if (by_depth) {
      const AppDepth& d = *eyes[e].depth;
      pe.depth_format = depth_packing(d.format);
      pe.depth_offset = l.depth_offset[e];
      pe.min_depth = d.range.min_depth;
      pe.max_depth = d.range.max_depth;
      pe.inv_near = inverse_plane(d.range.near_z);
      pe.inv_far = inverse_plane(d.range.far_z);
    }
  }
  p.mode = by_depth                         ? shaders::kLayerDepth
           : rule.mode == Composite::AppOnTop ? shaders::kLayerAppOnTop
           : rule.mode == Composite::Alpha    ? shaders::kLayerAlpha
                                              : shaders::kLayerSceneOnly;
  p.auto_background = !rule.background;
  p.background = rule.background ? std::uint32_t((*rule.background)[0]) | std::uint32_t((*rule.background)[1]) << 8 |
                                       std::uint32_t((*rule.background)[2]) << 16
                                 : 0u;
  p.tolerance = 2;  // composite()'s default
  p.source_alpha = rule.blend.source_alpha;
  p.premultiplied = rule.blend.premultiplied;
  p.srgb = rule.blend.srgb;
  if (g.decode_srgb != rule.blend.srgb) {
    for (int i = 0; i < 256; ++i)
      g.decode[std::size_t(i)] = rule.blend.srgb ? core::srgb_decode(float(i) / 255.0f) : float(i) / 255.0f;
    g.decode_srgb = rule.blend.srgb;
  }
  std::memcpy(p.decode, g.decode.data(), sizeof p.decode);

  reserve_gpu_buffers(l.app_bytes, l.depth_bytes);
  // A pass recorded for these images and no longer in flight. Else, if one is recorded for
  // them but in flight, a second copy in a pass never recorded, or (none left) a wait for the
  // least recently used copy: copies never evict each other, so recordings stop once there
  // are enough. Images never seen: a pass not in flight, the least recently used, recorded
  // for them (or, every pass in flight, the least recently used one after a wait). A pass's
  // previous submission must be done before its command buffer and parameter block are
  // reused: the only host wait.
  const auto older = [&](std::size_t i, std::size_t j) {  // unrecorded first, then least recently used
    const Pass &a = g.passes[i], &b = g.passes[j];
    return a.recorded != b.recorded ? !a.recorded : a.used < b.used;
  };
  std::size_t index = kPasses, fresh = kPasses, idle = kPasses, same = kPasses, any = kPasses;
  // The passes recorded for these images first: in the steady state one of them is idle, and
  // only their fences are polled.
  for (std::size_t i = 0; i < kPasses && index == kPasses; ++i)
    if (g.passes[i].recorded && g.passes[i].key == key && !pass_pending(g.passes[i])) index = i;
  for (std::size_t i = 0; i < kPasses && index == kPasses; ++i) {
    const bool matches = g.passes[i].recorded && g.passes[i].key == key;
    const bool in_flight = matches || pass_pending(g.passes[i]);  // the matching ones were polled above
    if (!g.passes[i].recorded && fresh == kPasses) fresh = i;
    if (!in_flight && (idle == kPasses || older(i, idle))) idle = i;
    if (matches && (same == kPasses || older(i, same))) same = i;
    if (any == kPasses || older(i, any)) any = i;
  }
  bool record = false;
  if (index == kPasses) {
    const std::size_t copy = same != kPasses ? fresh : idle;
    record = copy != kPasses || same == kPasses;
    index = copy != kPasses ? copy : same != kPasses ? same : any;
  }
  Pass& pass = g.passes[index];
  wait_pass(pass, g.counters.reuse_waits);
  if (record) {
    pass.key = key;
    record_pass(pass, index);
  }
  std::memcpy(static_cast<std::uint8_t*>(g.params.mapped) + g.params_stride * index, &p, sizeof p);
  app_check(vkResetFences_(device_, 1, &pass.fence), "vkResetFences");
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &pass.cb;
  // The involuntary context switches of this thread during the submission: on lavapipe it
  // wakes the device's queue thread, which runs the pass and may take this thread's core.
  rusage before{}, after{};
  getrusage(RUSAGE_THREAD, &before);
  const core::TimeNs t_submit = core::now_ns();
  app_check(vkQueueSubmit_(queue_handle_, 1, &si, pass.fence), "vkQueueSubmit");
  g.counters.submit_ms = core::ns_to_ms(core::now_ns() - t_submit);
  getrusage(RUSAGE_THREAD, &after);
  g.counters.submit_preemptions = after.ru_nivcsw - before.ru_nivcsw;
  pass.pending = true;
  pass.slot = slot;
  pass.used = ++g.clock;
  ++g.counters.submissions;
}

}  // namespace fovea::layer
