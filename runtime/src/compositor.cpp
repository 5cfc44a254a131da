#include "compositor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "fovea/compositor/distortion.hpp"
#include "fovea/core/clock.hpp"
#include "fovea/core/error.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/shaders/xr_readback.h"
#include "log.hpp"

namespace fovea::runtime {
namespace {

using shaders::kReadbackGroup;
using shaders::ReadbackPush;

bool same_fov(const core::Fov& a, const core::Fov& b) {
  constexpr double eps = 1e-6;
  return std::abs(a.angle_left - b.angle_left) < eps && std::abs(a.angle_right - b.angle_right) < eps &&
         std::abs(a.angle_up - b.angle_up) < eps && std::abs(a.angle_down - b.angle_down) < eps;
}

glm::vec4 bilinear(const core::Image& img, glm::dvec2 px) {
  // Pixel centres at +0.5; clamp to the edge.
  const double x = std::clamp(px.x - 0.5, 0.0, double(img.width - 1));
  const double y = std::clamp(px.y - 0.5, 0.0, double(img.height - 1));
  const int x0 = int(x), y0 = int(y);
  const int x1 = std::min(x0 + 1, img.width - 1), y1 = std::min(y0 + 1, img.height - 1);
  const float fx = float(x - x0), fy = float(y - y0);
  const glm::vec4 top = glm::mix(img.at(x0, y0), img.at(x1, y0), fx);
  const glm::vec4 bottom = glm::mix(img.at(x0, y1), img.at(x1, y1), fx);
  return glm::mix(top, bottom, fy);
}

// Which pixels of the rendered view anyone can see through the lens (1) — inverse optics
// per pixel, so computed once per eye.
std::vector<std::uint8_t> visible_pixels(const core::View& view, const core::HiddenAreaMask& hidden) {
  std::vector<std::uint8_t> v(size_t(view.width()) * view.height());
  for (int y = 0; y < view.height(); ++y)
    for (int x = 0; x < view.width(); ++x)
      v[size_t(y) * view.width() + x] = hidden.visible(view.pixel_to_dir({x + 0.5, y + 0.5})) ? 1 : 0;
  return v;
}

}  // namespace

LensMode parse_lens_mode(const std::string& s) {
  if (s == "gpu") return LensMode::Gpu;
  if (s == "cpu") return LensMode::Cpu;
  if (s == "off") return LensMode::Off;
  throw core::InputError("FOVEA_RUNTIME_LENS=" + s + ": expected gpu, cpu or off");
}

bool Compositor::readable_format(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_R8G8B8A8_UNORM ||
         f == VK_FORMAT_B8G8R8A8_UNORM;
}

Compositor::Compositor(VkPhysicalDevice physical, VkDevice device, OneShotQueue& queue,
                       const core::DisplayPreset& display, std::array<const core::HiddenAreaMask*, 2> hidden,
                       LensMode lens, std::string out_dir, std::int64_t png_every)
    : physical_(physical),
      device_(device),
      queue_(queue),
      display_(display),
      hidden_(hidden),
      lens_(lens),
      out_dir_(std::move(out_dir)),
      png_every_(png_every),
      marker_config_(compositor::marker_config([](const char* name) -> const char* { return std::getenv(name); })),
      marker_(marker_config_) {
  const char* mode = lens_ == LensMode::Gpu   ? "lens distortion + hidden area (GPU pass)"
                     : lens_ == LensMode::Cpu ? "lens distortion + hidden area (CPU reference)"
                                              : "undistorted view + hidden area";
  FOVEA_LOG_INFO("compositor: %s, lens model %s, hidden area %.1f%% of the left panel", mode,
                 core::lens_model_name(hidden_[0]->lens().kind()), 100.0 * hidden_[0]->hidden_fraction());
}

Compositor::~Compositor() {
  for (auto& p : passes_) p.reset();  // before their context
  gpu_.reset();
  if (pool_) vkDestroyDescriptorPool(device_, pool_, nullptr);
  gpu::destroy_foreign_pipelines(device_, &vkGetDeviceProcAddr, program_);
  if (sampler_) vkDestroySampler(device_, sampler_, nullptr);
  if (staging_) vkDestroyBuffer(device_, staging_, nullptr);
  if (staging_memory_) vkFreeMemory(device_, staging_memory_, nullptr);
}

void Compositor::ensure_staging(VkDeviceSize bytes) {
  if (bytes <= staging_size_) return;
  if (staging_) vkDestroyBuffer(device_, staging_, nullptr);
  if (staging_memory_) vkFreeMemory(device_, staging_memory_, nullptr);
  staging_ = VK_NULL_HANDLE;
  staging_memory_ = VK_NULL_HANDLE;
  staging_size_ = 0;
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = bytes;
  bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  bi.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  vk_check(vkCreateBuffer(device_, &bi, nullptr, &staging_), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, staging_, &req);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = find_memory_type(physical_, req.memoryTypeBits,
                                        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  vk_check(vkAllocateMemory(device_, &ai, nullptr, &staging_memory_), "vkAllocateMemory");
  vk_check(vkBindBufferMemory(device_, staging_, staging_memory_, 0), "vkBindBufferMemory");
  staging_size_ = bytes;
}

void Compositor::ensure_pipeline() {
  if (!program_.pipelines.empty()) return;
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = VK_FILTER_NEAREST;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  vk_check(vkCreateSampler(device_, &si, nullptr, &sampler_), "vkCreateSampler");
  gpu::ForeignPipelineDesc desc{"xr_readback.comp.spv", {}, sizeof(ReadbackPush), {}};
  desc.bindings.resize(2);
  desc.bindings[READBACK_BINDING_SOURCE] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  desc.bindings[READBACK_BINDING_OUT] = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  program_ = gpu::create_foreign_pipelines(device_, &vkGetDeviceProcAddr, desc);
  const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1},
                                         {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}};
  VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pi.maxSets = 1;
  pi.poolSizeCount = 2;
  pi.pPoolSizes = sizes;
  vk_check(vkCreateDescriptorPool(device_, &pi, nullptr, &pool_), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = pool_;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &program_.set_layout;
  vk_check(vkAllocateDescriptorSets(device_, &ai, &set_), "vkAllocateDescriptorSets");
}

core::Image Compositor::read_back(const LayerView& v) {
  const int w = v.rect.extent.width, h = v.rect.extent.height;
  ensure_pipeline();
  ensure_staging(VkDeviceSize(w) * h * sizeof(glm::vec4));
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = v.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
  vi.format = v.format;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, v.array_layer, 1};
  VkImageView view = VK_NULL_HANDLE;
  vk_check(vkCreateImageView(device_, &vi, nullptr, &view), "vkCreateImageView");
  struct ViewGuard {
    VkDevice d;
    VkImageView v;
    ~ViewGuard() { vkDestroyImageView(d, v, nullptr); }
  } guard{device_, view};
  const VkDescriptorImageInfo ii{sampler_, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  const VkDescriptorBufferInfo bi{staging_, 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet writes[2] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}, {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}};
  writes[0].dstSet = writes[1].dstSet = set_;
  writes[0].dstBinding = READBACK_BINDING_SOURCE;
  writes[0].descriptorCount = 1;
  writes[0].descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  writes[0].pImageInfo = &ii;
  writes[1].dstBinding = READBACK_BINDING_OUT;
  writes[1].descriptorCount = 1;
  writes[1].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  writes[1].pBufferInfo = &bi;
  vkUpdateDescriptorSets(device_, 2, writes, 0, nullptr);
  const ReadbackPush push{v.rect.offset.x, v.rect.offset.y, std::uint32_t(w), std::uint32_t(h), v.array_layer};
  queue_.run([&](VkCommandBuffer cmd) {
    transition(cmd, v.image, false, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
               VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT,
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, program_.pipelines[0]);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, program_.layout, 0, 1, &set_, 0, nullptr);
    vkCmdPushConstants(cmd, program_.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatch(cmd, (std::uint32_t(w) + kReadbackGroup - 1) / kReadbackGroup,
                  (std::uint32_t(h) + kReadbackGroup - 1) / kReadbackGroup, 1);
    transition(cmd, v.image, false, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
               VK_ACCESS_SHADER_READ_BIT, VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
               VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT);
    VkBufferMemoryBarrier hb{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    hb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    hb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    hb.srcQueueFamilyIndex = hb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    hb.buffer = staging_;
    hb.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1, &hb,
                         0, nullptr);
  });
  void* mapped = nullptr;
  vk_check(vkMapMemory(device_, staging_memory_, 0, VK_WHOLE_SIZE, 0, &mapped), "vkMapMemory");
  // The view already decoded sRGB and swizzled BGRA; non-finite texels never reach the panel.
  core::Image img(w, h);
  const auto* texels = static_cast<const glm::vec4*>(mapped);
  for (size_t i = 0; i < img.pixels.size(); ++i) {
    const glm::vec4 c = texels[i];
    img.pixels[i] = glm::vec4(std::isfinite(c.x) ? c.x : 0, std::isfinite(c.y) ? c.y : 0,
                              std::isfinite(c.z) ? c.z : 0, std::isfinite(c.w) ? c.w : 1);
  }
  vkUnmapMemory(device_, staging_memory_);
  return img;
}

void Compositor::observe_frame(std::int64_t index, const GazeSample& gaze, core::TimeNs displayed_ns) {
  if (marker_config_.mode == compositor::MarkerMode::Off) return;
  if (gaze.sample_ns != last_gaze_ns_) {  // each real sample once
    last_gaze_ns_ = gaze.sample_ns;
    devices::GazeSample s;
    s.t_ns = gaze.sample_ns;
    s.combined = {gaze.dir, gaze.valid ? 1.0 : 0.0, gaze.valid ? devices::kTracked : devices::kLost};
    if (onsets_.add(s)) marker_.trigger(gaze.sample_ns);
  }
  const compositor::MarkerSchedule::Frame f = marker_.next_frame();
  lit_frame_ = f.lit ? index : -1;
  if (!f.first || out_dir_.empty()) return;
  std::ofstream log(out_dir_ + "/marker.jsonl", std::ios::app);
  log << "{\"frame\":" << index << ",\"event_sample_ns\":"
      << (f.event_sample_ns ? std::to_string(*f.event_sample_ns) : std::string("null")) << ",\"displayed_ns\":" << displayed_ns
      << ",\"mode\":\"" << (marker_config_.mode == compositor::MarkerMode::Saccade ? "saccade" : "periodic")
      << "\",\"frames\":" << marker_config_.frames << ",\"size_px\":" << marker_config_.size_px << "}\n";
  if (!log) FOVEA_LOG_ERROR("marker: cannot append to %s/marker.jsonl", out_dir_.c_str());
}

ComposeTimes Compositor::compose(std::int64_t index, const std::vector<ProjectionLayer>& layers) {
  ComposeTimes times;
  core::TimeNs mark = core::now_ns();
  // Adds the time since the previous mark to `ms`.
  const auto lap = [&mark](double& ms) {
    const core::TimeNs t = core::now_ns();
    ms += core::ns_to_ms(t - mark);
    mark = t;
  };
  for (int e = 0; e < 2; ++e) {
    const core::Eye eye = e == 0 ? core::Eye::Left : core::Eye::Right;
    const core::View view = display_.view(eye);
    core::Image rendered(display_.width, display_.height, {0, 0, 0, 1});
    for (const ProjectionLayer& layer : layers) {
      const LayerView& lv = layer.views[size_t(e)];
      lap(times.resample_ms);
      const core::Image src = read_back(lv);
      lap(times.readback_ms);
      const bool copy = same_fov(lv.fov, display_.fov(eye)) && src.width == rendered.width && src.height == rendered.height;
      const core::View layer_view(lv.fov, src.width, src.height);
      for (int y = 0; y < rendered.height; ++y)
        for (int x = 0; x < rendered.width; ++x) {
          glm::vec4 c;
          if (copy) {
            c = src.at(x, y);
          } else {
            const auto p = layer_view.dir_to_pixel(view.pixel_to_dir({x + 0.5, y + 0.5}));
            if (!p || !layer_view.contains_pixel(*p)) continue;  // outside the layer: unchanged
            c = bilinear(src, *p);
          }
          glm::vec4& dst = rendered.at(x, y);
          dst = layer.alpha_blend ? glm::vec4(glm::vec3(c) * c.w + glm::vec3(dst) * (1 - c.w), 1) : glm::vec4(glm::vec3(c), 1);
        }
    }
    lap(times.resample_ms);
    const core::HiddenAreaMask& hidden = *hidden_[size_t(e)];
    core::Image panel;
    if (lens_ == LensMode::Gpu) {
      if (!gpu_) {
        gpu_ = std::make_unique<gpu::Context>();
        for (int i = 0; i < 2; ++i) passes_[size_t(i)] = std::make_unique<compositor::DistortionPass>(*gpu_, *hidden_[size_t(i)]);
        FOVEA_LOG_INFO("compositor: distortion pass on \"%s\"", gpu_->info().name.c_str());
      }
      panel = passes_[size_t(e)]->run(rendered).to_image();
    } else if (lens_ == LensMode::Cpu) {
      panel = compositor::distort_reference(hidden, rendered);
    } else {
      auto& visible = visible_[size_t(e)];
      if (visible.empty()) visible = visible_pixels(view, hidden);
      for (size_t i = 0; i < visible.size(); ++i)
        if (!visible[i]) rendered.pixels[i] = {0, 0, 0, 1};
      panel = std::move(rendered);
    }
    if (marker_config_.mode != compositor::MarkerMode::Off)
      compositor::draw_marker(panel, marker_config_.corner, marker_config_.size_px, lit_frame_ == index);
    lap(times.lens_ms);
    char name[64];
    std::snprintf(name, sizeof name, "/panel_%06lld_%s.png", static_cast<long long>(index), core::eye_name(eye));
    core::write_png(out_dir_ + name, panel);
    lap(times.write_ms);
  }
  return times;
}

}  // namespace fovea::runtime
