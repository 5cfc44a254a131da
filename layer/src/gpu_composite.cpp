// The layer's composition as a compute pass on the application's device (AppDevice::composite_gpu):
// xr_layer_composite.comp runs resample() and composite() of composite.cpp on packed 8-bit
// pixels in device buffers. Per traced frame its two eye images are uploaded once; per
// application frame one submission on the session queue copies the application's projection
// views into a buffer (the TRANSFER_SRC usage the layer requests), finds AppOnTop's background
// on the border, composites both eyes and copies the results into the layer's swapchain
// images. Nothing of the application's images reaches the host.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "app_device.hpp"
#include "fovea/core/image.hpp"
#include "fovea/shaders/embedded.hpp"
#include "fovea/shaders/layer_composite.h"

namespace fovea::layer {

namespace {

constexpr std::uint32_t kBindings = 6;
// The composite pass's workgroup.
constexpr std::uint32_t kGroupX = 32, kGroupY = 8;

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

VkMemoryBarrier memory_barrier(VkAccessFlags src, VkAccessFlags dst) {
  VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  b.srcAccessMask = src;
  b.dstAccessMask = dst;
  return b;
}

}  // namespace

void AppDevice::enable_gpu_composition() {
  if (gpu_) return;
  if (!family_has_compute_)
    throw std::runtime_error("the session's queue family " + std::to_string(queue_family_) + " has no compute");
  const auto spv = shaders::find("xr_layer_composite.comp.spv");
  if (spv.empty()) throw std::runtime_error("xr_layer_composite.comp.spv is not embedded");
  gpu_ = std::make_unique<Gpu>();
  Gpu& g = *gpu_;
  try {
    VkDescriptorSetLayoutBinding b[kBindings]{};
    for (std::uint32_t i = 0; i < kBindings; ++i)
      b[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    li.bindingCount = kBindings;
    li.pBindings = b;
    app_check(vkCreateDescriptorSetLayout_(device_, &li, nullptr, &g.set_layout), "vkCreateDescriptorSetLayout");
    const VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(Push)};
    VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pli.setLayoutCount = 1;
    pli.pSetLayouts = &g.set_layout;
    pli.pushConstantRangeCount = 1;
    pli.pPushConstantRanges = &push;
    app_check(vkCreatePipelineLayout_(device_, &pli, nullptr, &g.layout), "vkCreatePipelineLayout");
    VkShaderModuleCreateInfo mi{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    mi.codeSize = spv.size();
    mi.pCode = reinterpret_cast<const std::uint32_t*>(spv.data());
    app_check(vkCreateShaderModule_(device_, &mi, nullptr, &g.shader), "vkCreateShaderModule");
    // One pipeline per pass (specialisation constants 0: the pass, 1 and 2: the workgroup size).
    for (const std::uint32_t pass : {shaders::kLayerPassBorder, shaders::kLayerPassComposite}) {
      const bool border = pass == shaders::kLayerPassBorder;
      const std::uint32_t values[3] = {pass, border ? shaders::kLayerBorderGroup : kGroupX, border ? 1u : kGroupY};
      const VkSpecializationMapEntry entries[3] = {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}};
      const VkSpecializationInfo spec{3, entries, sizeof values, values};
      VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
      ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
      ci.stage.module = g.shader;
      ci.stage.pName = "main";
      ci.stage.pSpecializationInfo = &spec;
      ci.layout = g.layout;
      app_check(vkCreateComputePipelines_(device_, VK_NULL_HANDLE, 1, &ci, nullptr,
                                          pass == shaders::kLayerPassBorder ? &g.border_pipeline : &g.pipeline),
                "vkCreateComputePipelines");
    }
    const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBindings};
    VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pi.maxSets = 1;
    pi.poolSizeCount = 1;
    pi.pPoolSizes = &size;
    app_check(vkCreateDescriptorPool_(device_, &pi, nullptr, &g.pool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = g.pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &g.set_layout;
    app_check(vkAllocateDescriptorSets_(device_, &ai, &g.set), "vkAllocateDescriptorSets");
    constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    reserve(g.params, sizeof(shaders::LayerCompositeParams), storage);
    reserve(g.background, 2 * sizeof(std::uint32_t), storage, false);
    constexpr std::uint64_t kTimeoutNs = 10'000'000'000;
    pass_ = std::make_unique<xrcommon::ForeignQueue>(device_, get_device_proc_, queue_family_, queue_handle_, kTimeoutNs,
                                                     "the application's device");
  } catch (...) {
    destroy_gpu();
    throw;
  }
}

void AppDevice::finish() {
  std::lock_guard lock(pass_mutex_);
  if (pass_) pass_->wait();
}

void AppDevice::destroy_gpu() {
  pass_.reset();  // waits for a pass still running: it uses the buffers below
  if (!gpu_) return;
  Gpu& g = *gpu_;
  for (Buffer* b : {&g.params, &g.staging, &g.traced, &g.app, &g.app_depth, &g.out, &g.background}) release(*b);
  if (g.pool) vkDestroyDescriptorPool_(device_, g.pool, nullptr);
  if (g.pipeline) vkDestroyPipeline_(device_, g.pipeline, nullptr);
  if (g.border_pipeline) vkDestroyPipeline_(device_, g.border_pipeline, nullptr);
  if (g.shader) vkDestroyShaderModule_(device_, g.shader, nullptr);
  if (g.layout) vkDestroyPipelineLayout_(device_, g.layout, nullptr);
  if (g.set_layout) vkDestroyDescriptorSetLayout_(device_, g.set_layout, nullptr);
  gpu_.reset();
}

void AppDevice::composite_gpu(std::int64_t traced_id, const std::array<GpuEye, 2>& eyes, const CompositionRule& rule) {
  if (!gpu_) throw std::logic_error("composite_gpu: GPU composition was not enabled");
  Gpu& g = *gpu_;
  std::lock_guard lock(pass_mutex_);
  pass_->wait();  // the previous frame's pass reads the buffers rewritten below
  const bool with_app = rule.mode != Composite::SceneOnly;
  // By depth when both eyes bring the application's depth image and the traced depths.
  const bool by_depth = with_app && eyes[0].depth && eyes[1].depth && eyes[0].composition.traced_depth &&
                        eyes[1].composition.traced_depth;
  auto& p = *static_cast<shaders::LayerCompositeParams*>(g.params.mapped);
  std::uint32_t traced_px = 0, app_px = 0, out_px = 0;
  VkDeviceSize depth_bytes = 0;
  for (std::size_t e = 0; e < 2; ++e) {
    const EyeComposition& c = eyes[e].composition;
    shaders::LayerCompositeEye& pe = p.eye[e];
    const XrExtent2Di app_size = eyes[e].app.rect.extent;
    if (with_app && (app_size.width <= 0 || app_size.height <= 0 || eyes[e].app.rect.offset.x < 0 ||
                     eyes[e].app.rect.offset.y < 0))
      throw std::runtime_error("a submitted imageRect is empty or negative");
    set_tan(pe.out_tan, c.out_view);
    set_tan(pe.traced_tan, c.traced_view);
    const glm::dmat3 r = glm::mat3_cast(c.to_traced);
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 3; ++col) pe.to_traced[row * 3 + col] = float(r[col][row]);  // glm: column-major
    pe.out_w = c.out_view.width();
    pe.out_h = c.out_view.height();
    pe.traced_w = c.traced_view.width();
    pe.traced_h = c.traced_view.height();
    pe.app_w = with_app ? app_size.width : 0;
    pe.app_h = with_app ? app_size.height : 0;
    pe.traced_offset = traced_px;
    pe.app_offset = app_px;
    pe.out_offset = out_px;
    // resample()'s shortcut, taken alike: a copy without resampling.
    pe.traced_identity = resample_copies(c.traced_view, pe.traced_w, pe.traced_h, c.out_view, c.to_traced);
    pe.app_identity = with_app && resample_copies(c.app_view, pe.app_w, pe.app_h, c.out_view);
    pe.depth_format = pe.depth_offset = 0;
    if (by_depth) {
      const AppDepth& d = *eyes[e].depth;
      if (d.rect.extent.width != app_size.width || d.rect.extent.height != app_size.height || d.rect.offset.x < 0 ||
          d.rect.offset.y < 0)
        throw std::runtime_error("a submitted depth imageRect differs in size from its colour imageRect");
      if (c.traced_depth->size() != std::size_t(pe.traced_w) * std::size_t(pe.traced_h))
        throw std::logic_error("composite_gpu: the traced depths differ from its view's raster");
      pe.depth_format = depth_packing(d.format);
      pe.depth_offset = std::uint32_t(depth_bytes);
      // Offsets stay multiples of 4 (buffer copies of depth aspects require it).
      depth_bytes += (VkDeviceSize(app_size.width) * VkDeviceSize(app_size.height) *
                          (pe.depth_format == shaders::kLayerDepthD16 ? 2 : 4) + 3) & ~VkDeviceSize(3);
      pe.min_depth = d.range.min_depth;
      pe.max_depth = d.range.max_depth;
      pe.inv_near = inverse_plane(d.range.near_z);
      pe.inv_far = inverse_plane(d.range.far_z);
    }
    traced_px += std::uint32_t(pe.traced_w * pe.traced_h);
    app_px += std::uint32_t(pe.app_w * pe.app_h);
    out_px += std::uint32_t(pe.out_w * pe.out_h);
  }
  // The traced depths follow both eyes' colour.
  p.eye[0].traced_depth_offset = traced_px;
  p.eye[1].traced_depth_offset = traced_px + std::uint32_t(p.eye[0].traced_w * p.eye[0].traced_h);
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
  for (int i = 0; i < 256; ++i) p.decode[i] = rule.blend.srgb ? core::srgb_decode(float(i) / 255.0f) : float(i) / 255.0f;

  constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  // The traced colour, then (by depth) its depths: 4 bytes per pixel each.
  const VkDeviceSize traced_bytes = VkDeviceSize(traced_px) * 4 * (by_depth ? 2 : 1);
  // A new traced frame, its depths needed for the first time, or a buffer that has to grow
  // (first use): its contents are uploaded.
  const bool upload = traced_id != g.uploaded || (by_depth && !g.uploaded_depth) || g.traced.size < traced_bytes;
  if (upload) {
    reserve(g.staging, traced_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    auto* staging = static_cast<std::uint8_t*>(g.staging.mapped);
    for (std::size_t e = 0; e < 2; ++e) {
      const Pixels8& t = *eyes[e].composition.traced;
      if (t.width != p.eye[e].traced_w || t.height != p.eye[e].traced_h)
        throw std::logic_error("composite_gpu: the traced image differs from its view's raster");
      std::memcpy(staging + std::size_t(p.eye[e].traced_offset) * 4, t.data.data(), t.data.size());
      if (by_depth)
        std::memcpy(staging + std::size_t(p.eye[e].traced_depth_offset) * 4, eyes[e].composition.traced_depth->data(),
                    eyes[e].composition.traced_depth->size() * sizeof(float));
    }
  }
  reserve(g.traced, traced_bytes, storage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false);
  reserve(g.app, std::max<VkDeviceSize>(VkDeviceSize(app_px) * 4, 4), storage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false);
  reserve(g.app_depth, std::max<VkDeviceSize>(depth_bytes, 4), storage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false);
  reserve(g.out, VkDeviceSize(out_px) * 4, storage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false);

  // Buffers may have been reallocated: the set names the current ones.
  const Buffer* bound[kBindings] = {&g.params, &g.traced, &g.app, &g.out, &g.background, &g.app_depth};
  VkDescriptorBufferInfo infos[kBindings];
  VkWriteDescriptorSet writes[kBindings];
  for (std::uint32_t i = 0; i < kBindings; ++i) {
    infos[i] = {bound[i]->buffer, 0, VK_WHOLE_SIZE};
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = g.set;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  vkUpdateDescriptorSets_(device_, kBindings, writes, 0, nullptr);

  if (upload) {
    g.uploaded = traced_id;
    g.uploaded_depth = by_depth;
  }
  // One submission, not waited for here: the copies of the application's images end with a
  // barrier whose second scope spans every later submission on the queue, so the
  // application's next rendering into them waits for the copies on the device, and the
  // runtime waits for the session queue's work before it reads the layer's images (as for
  // any application's). xrEndFrame then costs the recording and the submission only.
  pass_->submit([&](VkCommandBuffer cb) {
    if (upload) {
      const VkBufferCopy region{0, 0, traced_bytes};
      vkCmdCopyBuffer_(cb, g.staging.buffer, g.traced.buffer, 1, &region);
    }
    if (with_app)
      for (std::size_t e = 0; e < 2; ++e)
        record_download(cb,
                        {eyes[e].app.image, eyes[e].app.array_layer, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                         VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                         VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_ASPECT_COLOR_BIT, eyes[e].app.rect,
                         VkDeviceSize(p.eye[e].app_offset) * 4},
                        g.app.buffer);
    if (by_depth)
      for (std::size_t e = 0; e < 2; ++e) {
        const AppDepth& d = *eyes[e].depth;
        record_download(cb, depth_download(d, VkDeviceSize(p.eye[e].depth_offset)), g.app_depth.buffer);
      }
    // After the copies above; the parameters' host writes are visible through the submission.
    const VkMemoryBarrier to_compute = memory_barrier(VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT);
    vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &to_compute, 0,
                          nullptr, 0, nullptr);
    vkCmdBindDescriptorSets_(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.layout, 0, 1, &g.set, 0, nullptr);
    if (p.mode == shaders::kLayerAppOnTop && !rule.background) {
      vkCmdBindPipeline_(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.border_pipeline);
      for (std::uint32_t e = 0; e < 2; ++e) {
        const Push push{e};
        vkCmdPushConstants_(cb, g.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
        vkCmdDispatch_(cb, 1, 1, 1);
      }
      const VkMemoryBarrier border = memory_barrier(VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT);
      vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &border,
                            0, nullptr, 0, nullptr);
    }
    vkCmdBindPipeline_(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.pipeline);
    for (std::uint32_t e = 0; e < 2; ++e) {
      const Push push{e};
      vkCmdPushConstants_(cb, g.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
      vkCmdDispatch_(cb, (std::uint32_t(p.eye[e].out_w) + kGroupX - 1) / kGroupX,
                    (std::uint32_t(p.eye[e].out_h) + kGroupY * shaders::kLayerRowsPerInvocation - 1) /
                        (kGroupY * shaders::kLayerRowsPerInvocation), 1);
    }
    const VkMemoryBarrier to_transfer = memory_barrier(VK_ACCESS_SHADER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    vkCmdPipelineBarrier_(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &to_transfer,
                          0, nullptr, 0, nullptr);
    for (std::size_t e = 0; e < 2; ++e)
      record_upload(cb, g.out.buffer, VkDeviceSize(p.eye[e].out_offset) * 4, eyes[e].target, p.eye[e].out_w,
                    p.eye[e].out_h);
  });
}

}  // namespace fovea::layer
