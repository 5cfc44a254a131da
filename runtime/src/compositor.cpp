#include "compositor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "visibility_mask.hpp"

namespace fovea::runtime {
namespace {

bool is_bgra(VkFormat f) { return f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM; }
bool is_srgb(VkFormat f) { return f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_R8G8B8A8_SRGB; }

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

// Sign of the 2D cross product (b - a) x (p - a).
double edge(const XrVector2f& a, const XrVector2f& b, glm::dvec2 p) {
  return (double(b.x) - a.x) * (p.y - a.y) - (double(b.y) - a.y) * (p.x - a.x);
}

// Blacks out panel pixels whose centre falls inside a hidden-area triangle.
void apply_hidden_area(core::Image& panel, const core::View& view, const VisibilityMask& hidden) {
  if (hidden.indices.empty()) return;
  for (int y = 0; y < panel.height; ++y)
    for (int x = 0; x < panel.width; ++x) {
      const glm::dvec3 d = view.pixel_to_dir({x + 0.5, y + 0.5});
      const glm::dvec2 t(d.x / -d.z, d.y / -d.z);  // tangent plane z = -1, as the mask
      for (size_t i = 0; i + 2 < hidden.indices.size(); i += 3) {
        const XrVector2f& a = hidden.vertices[hidden.indices[i]];
        const XrVector2f& b = hidden.vertices[hidden.indices[i + 1]];
        const XrVector2f& c = hidden.vertices[hidden.indices[i + 2]];
        const double e0 = edge(a, b, t), e1 = edge(b, c, t), e2 = edge(c, a, t);
        if ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0)) {
          panel.at(x, y) = {0, 0, 0, 1};
          break;
        }
      }
    }
}

}  // namespace

bool Compositor::readable_format(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_R8G8B8A8_UNORM ||
         f == VK_FORMAT_B8G8R8A8_UNORM;
}

Compositor::Compositor(VkPhysicalDevice physical, VkDevice device, OneShotQueue& queue,
                       const core::DisplayPreset& display, std::string out_dir, std::int64_t png_every)
    : physical_(physical),
      device_(device),
      queue_(queue),
      display_(display),
      out_dir_(std::move(out_dir)),
      png_every_(png_every) {}

Compositor::~Compositor() {
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
  bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
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

core::Image Compositor::read_back(const LayerView& v) {
  const int w = v.rect.extent.width, h = v.rect.extent.height;
  ensure_staging(VkDeviceSize(w) * h * 4);
  queue_.run([&](VkCommandBuffer cmd) {
    transition(cmd, v.image, false, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT,
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy r{};
    r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, v.array_layer, 1};
    r.imageOffset = {v.rect.offset.x, v.rect.offset.y, 0};
    r.imageExtent = {uint32_t(w), uint32_t(h), 1};
    vkCmdCopyImageToBuffer(cmd, v.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging_, 1, &r);
    transition(cmd, v.image, false, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
               VK_ACCESS_TRANSFER_READ_BIT, VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
               VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT);
    VkBufferMemoryBarrier hb{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    hb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    hb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    hb.srcQueueFamilyIndex = hb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    hb.buffer = staging_;
    hb.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1, &hb, 0,
                         nullptr);
  });
  void* mapped = nullptr;
  vk_check(vkMapMemory(device_, staging_memory_, 0, VK_WHOLE_SIZE, 0, &mapped), "vkMapMemory");
  const auto* px = static_cast<const std::uint8_t*>(mapped);
  core::Image img(w, h);
  const bool bgra = is_bgra(v.format), srgb = is_srgb(v.format);
  for (int i = 0; i < w * h; ++i) {
    const std::uint8_t* p = px + size_t(i) * 4;
    glm::vec4 c(p[bgra ? 2 : 0], p[1], p[bgra ? 0 : 2], p[3]);
    c /= 255.0f;
    if (srgb) c = {core::srgb_decode(c.x), core::srgb_decode(c.y), core::srgb_decode(c.z), c.w};
    img.pixels[size_t(i)] = c;
  }
  vkUnmapMemory(device_, staging_memory_);
  return img;
}

void Compositor::compose(std::int64_t index, const std::vector<ProjectionLayer>& layers) {
  for (int e = 0; e < 2; ++e) {
    const core::Eye eye = e == 0 ? core::Eye::Left : core::Eye::Right;
    const core::View panel_view = display_.view(eye);
    core::Image panel(display_.width, display_.height, {0, 0, 0, 1});
    for (const ProjectionLayer& layer : layers) {
      const LayerView& lv = layer.views[size_t(e)];
      const core::Image src = read_back(lv);
      const bool copy = same_fov(lv.fov, display_.fov(eye)) && src.width == panel.width && src.height == panel.height;
      const core::View layer_view(lv.fov, src.width, src.height);
      for (int y = 0; y < panel.height; ++y)
        for (int x = 0; x < panel.width; ++x) {
          glm::vec4 c;
          if (copy) {
            c = src.at(x, y);
          } else {
            const auto p = layer_view.dir_to_pixel(panel_view.pixel_to_dir({x + 0.5, y + 0.5}));
            if (!p || !layer_view.contains_pixel(*p)) continue;  // outside the layer: unchanged
            c = bilinear(src, *p);
          }
          glm::vec4& dst = panel.at(x, y);
          dst = layer.alpha_blend ? glm::vec4(glm::vec3(c) * c.w + glm::vec3(dst) * (1 - c.w), 1) : glm::vec4(glm::vec3(c), 1);
        }
    }
    apply_hidden_area(panel, panel_view,
                      visibility_mask(display_, eye, XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR));
    char name[64];
    std::snprintf(name, sizeof name, "/panel_%06lld_%s.png", static_cast<long long>(index), core::eye_name(eye));
    core::write_png(out_dir_ + name, panel);
  }
}

}  // namespace fovea::runtime
