// The layer's GPU composition (xr_layer_composite.comp through AppDevice::composite_gpu) on
// the test's validated device, standing in for the application's, against the host path
// (compose_eye) on the same inputs: random traced frames and application images with a
// background colour, opaque, translucent and transparent pixels, for every mode and blend.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "app_device.hpp"
#include "composite.hpp"
#include "fovea/core/error.hpp"
#include "fovea/gpu/buffer.hpp"
#include "gpu_fixture.hpp"
#include "slot_writer.hpp"

namespace fovea::layer {
namespace {

// An image the way a runtime hands out swapchain images: device-local, transfer source and
// destination, colour (or, for a depth format, depth/stencil) attachment.
class TestImage {
 public:
  TestImage(gpu::Context& ctx, int w, int h, VkFormat format = VK_FORMAT_R8G8B8A8_UNORM) : device_(ctx.device()) {
    const bool depth = format == VK_FORMAT_D16_UNORM || format == VK_FORMAT_D32_SFLOAT;
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = format;
    ci.extent = {std::uint32_t(w), std::uint32_t(h), 1};
    ci.mipLevels = ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
               (depth ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
    EXPECT_EQ(vkCreateImage(device_, &ci, nullptr, &image_), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device_, image_, &req);
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(ctx.physical_device(), &mp);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    for (std::uint32_t i = 0; i < mp.memoryTypeCount; ++i)
      if (req.memoryTypeBits & (1u << i)) {
        ai.memoryTypeIndex = i;
        break;
      }
    EXPECT_EQ(vkAllocateMemory(device_, &ai, nullptr, &memory_), VK_SUCCESS);
    EXPECT_EQ(vkBindImageMemory(device_, image_, memory_, 0), VK_SUCCESS);
  }
  ~TestImage() {
    vkDestroyImage(device_, image_, nullptr);
    vkFreeMemory(device_, memory_, nullptr);
  }
  TestImage(const TestImage&) = delete;
  TestImage& operator=(const TestImage&) = delete;
  VkImage get() const { return image_; }

 private:
  VkDevice device_;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
};

Pixels8 random_scene(std::mt19937& rng, int w, int h) {
  Pixels8 p{w, h, std::vector<std::uint8_t>(std::size_t(w) * std::size_t(h) * 4)};
  for (std::size_t i = 0; i < p.data.size(); ++i) p.data[i] = i % 4 == 3 ? 255 : std::uint8_t(rng());
  return p;
}

// The application's image: its clear colour, with random rectangles of random pixels whose
// alpha is 0, 255 or anything between.
Pixels8 random_app(std::mt19937& rng, int w, int h, std::array<std::uint8_t, 3> clear) {
  Pixels8 p{w, h, std::vector<std::uint8_t>(std::size_t(w) * std::size_t(h) * 4)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* q = p.at(x, y);
      q[0] = clear[0], q[1] = clear[1], q[2] = clear[2], q[3] = 255;
    }
  for (int r = 0; r < 6; ++r) {
    const int x0 = int(rng() % std::uint32_t(w - 4)), y0 = int(rng() % std::uint32_t(h - 4));
    const int x1 = std::min(w, x0 + 3 + int(rng() % 12u)), y1 = std::min(h, y0 + 3 + int(rng() % 12u));
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        std::uint8_t* q = p.at(x, y);
        for (int c = 0; c < 3; ++c) q[c] = std::uint8_t(rng());
        const std::uint32_t a = rng() % 4u;
        q[3] = a == 0 ? 0 : a == 1 ? 255 : std::uint8_t(rng());
      }
  }
  return p;
}

// Pixels equal, off by one 8-bit step in some channel, off by more.
struct Differences {
  std::size_t exact = 0, rounding = 0, other = 0;
};
Differences differences(const Pixels8& a, const Pixels8& b) {
  Differences d;
  for (std::size_t i = 0; i < a.data.size() && i < b.data.size(); i += 4) {
    int worst = 0;
    for (std::size_t c = 0; c < 4; ++c) worst = std::max(worst, std::abs(int(a.data[i + c]) - int(b.data[i + c])));
    (worst == 0 ? d.exact : worst == 1 ? d.rounding : d.other)++;
  }
  return d;
}

glm::dquat yaw(double deg) { return glm::angleAxis(glm::radians(deg), glm::dvec3(0, 1, 0)); }

struct Geometry {
  const char* name;
  int traced_w, traced_h, app_w, app_h;
  core::Fov traced_fov, app_fov;
  double yaw_deg;
  // Pixels whose source pixel may differ (float against double at a pixel boundary).
  double boundary_fraction;
};

struct Mode {
  const char* name;
  Composite mode;
  bool fixed_background;
  XrCompositionLayerFlags flags;
  bool srgb;
};

// Eye `e` of geometry `g` (the right eye turned the other way), the traced frame `traced`.
EyeComposition eye_of(const Geometry& g, const Pixels8& traced, std::size_t e) {
  EyeComposition c;
  c.traced = &traced;
  c.traced_view = core::View(g.traced_fov, g.traced_w, g.traced_h);
  c.out_view = core::View(g.app_fov, g.traced_w, g.traced_h);
  c.to_traced = yaw(e == 0 ? g.yaw_deg : -g.yaw_deg);
  c.app_view = core::View(g.app_fov, g.app_w, g.app_h);
  return c;
}

// The traced frame of `jobs` (and its depths, when compositing by depth) written into a free
// slot, as the render thread does; the slot, retired once the caller has composited it.
int write_slot(AppDevice& dev, const std::array<AppDevice::GpuEye, 2>& jobs) {
  const int slot = dev.traced_slots()->claim();
  EXPECT_GE(slot, 0);
  for (int e = 0; e < 2; ++e) {
    const EyeComposition& c = jobs[std::size_t(e)].composition;
    std::memcpy(dev.slot_colour(slot, e), c.traced->data.data(), c.traced->data.size());
    if (c.traced_depth) std::memcpy(dev.slot_depth(slot, e), c.traced_depth->data(), c.traced_depth->size() * sizeof(float));
  }
  return slot;
}

// The GPU composition of `jobs`, its targets read back; it copies no application image to the host.
std::vector<Pixels8> composite_on_gpu(AppDevice& dev, const std::array<AppDevice::GpuEye, 2>& jobs,
                                      const CompositionRule& rule, const Geometry& g) {
  const std::int64_t readbacks = dev.host_readbacks();
  const int slot = write_slot(dev, jobs);
  dev.composite_gpu(slot, jobs, rule);
  dev.traced_slots()->retire(slot);  // released by a later composite_gpu, its pass done
  dev.finish();
  EXPECT_EQ(dev.host_readbacks(), readbacks) << "the GPU path copied application images to the host";
  return dev.read({{jobs[0].target, 0, {{0, 0}, {g.traced_w, g.traced_h}}},
                   {jobs[1].target, 0, {{0, 0}, {g.traced_w, g.traced_h}}}});
}

class GpuComposite : public test::GpuTest {};

TEST_F(GpuComposite, MatchesTheHostPathPixelByPixel) {
  const core::Fov fov{-0.7, 0.6, 0.65, -0.7};
  const Geometry geometries[] = {
      {"same views", 40, 36, 40, 36, fov, fov, 0.0, 0.0},
      {"reprojected and resampled", 40, 36, 52, 44, fov, {-0.72, 0.61, 0.66, -0.69}, 4.0, 0.02},
  };
  constexpr XrCompositionLayerFlags kAlpha = XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT;
  const Mode modes[] = {
      {"app-on-top, border colour", Composite::AppOnTop, false, 0, true},
      {"app-on-top, configured colour", Composite::AppOnTop, true, 0, false},
      {"alpha, opaque layer", Composite::Alpha, false, 0, true},
      {"alpha, premultiplied, sRGB", Composite::Alpha, false, kAlpha, true},
      {"alpha, premultiplied, UNORM", Composite::Alpha, false, kAlpha, false},
      {"alpha, unpremultiplied, sRGB", Composite::Alpha, false, kAlpha | XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT,
       true},
      {"scene only", Composite::SceneOnly, false, 0, true},
  };
  const VulkanBinding vk{ctx().instance(), ctx().physical_device(), ctx().device(), ctx().queue_family(), 0};
  AppDevice dev(vk);
  ASSERT_NO_THROW(dev.enable_gpu_composition(40, 36));
  std::mt19937 rng(1234);
  for (const Geometry& g : geometries) {
    TestImage app_img[2] = {{ctx(), g.app_w, g.app_h}, {ctx(), g.app_w, g.app_h}};
    TestImage target[2] = {{ctx(), g.traced_w, g.traced_h}, {ctx(), g.traced_w, g.traced_h}};
    for (const Mode& m : modes) {
      SCOPED_TRACE(std::string(g.name) + ", " + m.name);
      const std::array<std::uint8_t, 3> clear{30, 60, 90};
      std::array<Pixels8, 2> traced, app;
      for (int e = 0; e < 2; ++e) {
        traced[e] = random_scene(rng, g.traced_w, g.traced_h);
        app[e] = random_app(rng, g.app_w, g.app_h, clear);
      }
      dev.write({app_img[0].get(), app_img[1].get()}, {&app[0], &app[1]});
      CompositionRule rule;
      rule.mode = m.mode;
      if (m.fixed_background) rule.background = clear;
      rule.blend = layer_blend(m.flags, {false, m.srgb});
      std::array<AppDevice::GpuEye, 2> jobs;
      std::array<Pixels8, 2> host;
      for (std::size_t e = 0; e < 2; ++e) {
        EyeComposition c = eye_of(g, traced[e], e);
        jobs[e] = {c, {app_img[e].get(), 0, {{0, 0}, {g.app_w, g.app_h}}}, std::nullopt, target[e].get()};
        c.app = m.mode == Composite::SceneOnly ? nullptr : &app[e];
        host[e] = compose_eye(c, rule);
      }
      const std::vector<Pixels8> gpu_out = composite_on_gpu(dev, jobs, rule, g);
      for (std::size_t e = 0; e < 2; ++e) {
        ASSERT_EQ(gpu_out[e].data.size(), host[e].data.size());
        const auto [exact, rounding, other] = differences(gpu_out[e], host[e]);
        const std::size_t n = host[e].data.size() / 4;
        // Not vacuous: the application's pixels show in every mode but scene-only.
        EXPECT_LE(double(other), g.boundary_fraction * double(n)) << "eye " << e << ": " << other << " of " << n;
        if (g.boundary_fraction == 0) {
          EXPECT_EQ(other, 0u) << "eye " << e;
        }
        // Off by one only where the shader's sRGB/linear encoding rounds differently.
        EXPECT_LE(double(rounding), 0.02 * double(n)) << "eye " << e;
        EXPECT_GT(exact, n / 2) << "eye " << e;
      }
    }
  }
}

// The window depth of view distance `z` (+infinity: the infinite plane) under `r`: the inverse
// of view_distance(), t = (1/z - 1/near) / (1/far - 1/near).
float window_depth(double z, const DepthRange& r) {
  const auto inverse = [](double v) { return std::isinf(v) ? 0.0 : 1.0 / v; };
  const double t = (inverse(z) - inverse(r.near_z)) / (inverse(r.far_z) - inverse(r.near_z));
  return float(r.min_depth + t * (double(r.max_depth) - r.min_depth));
}

// `depths` (window depths, row-major) written into the depth aspect of `image`, which ends in
// DEPTH_STENCIL_ATTACHMENT_OPTIMAL as a runtime hands out depth swapchain images.
void fill_depth(gpu::Context& ctx, VkImage image, VkFormat format, int w, int h, const std::vector<float>& depths) {
  const bool d16 = format == VK_FORMAT_D16_UNORM;
  std::vector<std::byte> bytes(depths.size() * (d16 ? 2 : 4));
  for (std::size_t i = 0; i < depths.size(); ++i) {
    if (d16) {
      const auto v = std::uint16_t(std::lround(std::clamp(depths[i], 0.0f, 1.0f) * 65535.0f));
      std::memcpy(&bytes[i * 2], &v, 2);
    } else {
      std::memcpy(&bytes[i * 4], &depths[i], 4);
    }
  }
  gpu::Buffer staging(ctx, {VkDeviceSize(bytes.size()), gpu::BufferUsage::TransferSrc, gpu::Memory::HostVisible,
                            "depth staging"});
  std::memcpy(staging.mapped().data(), bytes.data(), bytes.size());
  ctx.submit_and_wait([&](VkCommandBuffer cb) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    VkBufferImageCopy c{};
    c.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    c.imageExtent = {std::uint32_t(w), std::uint32_t(h), 1};
    vkCmdCopyBufferToImage(cb, staging.handle(), image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT, 0, 0, nullptr,
                         0, nullptr, 1, &b);
  });
}

struct DepthCase {
  const char* name;
  VkFormat format;
  DepthRange range;
};

// Compositing by depth (the application chains XrCompositionLayerDepthInfoKHR) on the GPU
// against the host path: random traced colours and view distances (some sky), the
// application's pixels (some transparent) at random distances in front of and behind the
// scene and at its cleared far plane, for D32_SFLOAT, D16_UNORM, a partial and a reversed
// infinite range; same views, and a 4° reprojection with a resampled application image.
TEST_F(GpuComposite, ByDepthMatchesTheHostPath) {
  const core::Fov fov{-0.7, 0.6, 0.65, -0.7};
  const Geometry geometries[] = {
      {"same views", 40, 36, 40, 36, fov, fov, 0.0, 0.0},
      {"reprojected and resampled", 40, 36, 52, 44, fov, {-0.72, 0.61, 0.66, -0.69}, 4.0, 0.02},
  };
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const DepthCase cases[] = {
      {"D32_SFLOAT", VK_FORMAT_D32_SFLOAT, {0.0f, 1.0f, 0.1f, 100.0f}},
      {"D16_UNORM", VK_FORMAT_D16_UNORM, {0.0f, 1.0f, 0.05f, 20.0f}},
      {"D32_SFLOAT, partial range", VK_FORMAT_D32_SFLOAT, {0.2f, 0.8f, 0.1f, 50.0f}},
      {"D32_SFLOAT, reversed infinite", VK_FORMAT_D32_SFLOAT, {0.0f, 1.0f, kInf, 0.05f}},
  };
  const VulkanBinding vk{ctx().instance(), ctx().physical_device(), ctx().device(), ctx().queue_family(), 0};
  AppDevice dev(vk);
  ASSERT_NO_THROW(dev.enable_gpu_composition(40, 36));
  std::mt19937 rng(4321);
  std::uniform_real_distribution<double> distance(0.3, 5.0);
  for (const Geometry& g : geometries) {
    TestImage app_img[2] = {{ctx(), g.app_w, g.app_h}, {ctx(), g.app_w, g.app_h}};
    TestImage target[2] = {{ctx(), g.traced_w, g.traced_h}, {ctx(), g.traced_w, g.traced_h}};
    for (const DepthCase& dc : cases) {
      SCOPED_TRACE(std::string(g.name) + ", " + dc.name);
      TestImage depth_img[2] = {{ctx(), g.app_w, g.app_h, dc.format}, {ctx(), g.app_w, g.app_h, dc.format}};
      // The cleared far end: maxDepth, minDepth with reversed Z.
      const bool reversed = dc.range.near_z > dc.range.far_z;
      const float cleared = reversed ? dc.range.min_depth : dc.range.max_depth;
      std::array<Pixels8, 2> traced, app;
      std::array<std::vector<float>, 2> traced_depth, app_window;
      for (std::size_t e = 0; e < 2; ++e) {
        traced[e] = random_scene(rng, g.traced_w, g.traced_h);
        app[e] = random_app(rng, g.app_w, g.app_h, {30, 60, 90});
        for (int i = 0; i < g.traced_w * g.traced_h; ++i)
          traced_depth[e].push_back(rng() % 8u == 0 ? 0.0f : float(distance(rng)));  // 0: sky
        for (int i = 0; i < g.app_w * g.app_h; ++i)
          app_window.at(e).push_back(rng() % 4u == 0 ? cleared : window_depth(distance(rng), dc.range));
        fill_depth(ctx(), depth_img[e].get(), dc.format, g.app_w, g.app_h, app_window[e]);
      }
      dev.write({app_img[0].get(), app_img[1].get()}, {&app[0], &app[1]});
      const XrRect2Di rect{{0, 0}, {g.app_w, g.app_h}};
      const std::array<AppDepth, 2> depth{AppDepth{depth_img[0].get(), dc.format, rect, 0, dc.range},
                                          AppDepth{depth_img[1].get(), dc.format, rect, 0, dc.range}};
      // The host path: the depths read back and decoded, composited on the CPU.
      const std::vector<std::vector<float>> decoded = dev.read_depth({depth[0], depth[1]});
      CompositionRule rule;  // ignored by depth (the configured mode, app-on-top)
      std::array<AppDevice::GpuEye, 2> jobs;
      std::array<Pixels8, 2> host;
      std::array<std::int64_t, 2> host_kept{};
      for (std::size_t e = 0; e < 2; ++e) {
        EyeComposition c = eye_of(g, traced[e], e);
        c.traced_depth = &traced_depth[e];
        c.depth_range = dc.range;
        jobs[e] = {c, {app_img[e].get(), 0, rect}, depth[e], target[e].get()};
        c.app = &app[e];
        c.app_depth = &decoded[e];
        ASSERT_TRUE(c.by_depth());
        host[e] = compose_eye(c, rule);
        host_kept[e] = 0;
        const Pixels8 scene = reproject_traced(c);
        for (std::size_t i = 0; i < scene.data.size(); i += 4)
          host_kept[e] += std::memcmp(&scene.data[i], &host[e].data[i], 4) != 0;
      }
      const std::vector<Pixels8> gpu_out = composite_on_gpu(dev, jobs, rule, g);
      for (std::size_t e = 0; e < 2; ++e) {
        const std::size_t n = host[e].data.size() / 4;
        // Not vacuous: the application is in front in some pixels and behind the scene or
        // cleared in others.
        EXPECT_GT(host_kept[e], std::int64_t(n / 20)) << "eye " << e;
        EXPECT_LT(host_kept[e], std::int64_t(n / 2)) << "eye " << e;
        const auto [exact, rounding, other] = differences(gpu_out[e], host[e]);
        // Kept or scene pixels, no blending: identical but where a pixel takes its
        // neighbour's source at a boundary of the reprojection or resampling (float against
        // double), or a depth comparison falls within float rounding of a tie (none here).
        EXPECT_EQ(rounding, 0u) << "eye " << e;
        EXPECT_LE(double(other), g.boundary_fraction * double(n)) << "eye " << e << ": " << other << " of " << n;
      }
    }
  }
}

// The application's thread records a composition pass once per set of images and then only
// writes each frame's parameters and submits it: three frames on the same images with their
// own traced frames and head rotations need one recording and one descriptor update, and each
// matches the host path (stale parameters would not). Waiting for an acquired image waits only
// for the passes that read it.
TEST_F(GpuComposite, RecordsOncePerImagesAndWaitsOnlyForPassesOnTheImage) {
  const core::Fov fov{-0.7, 0.6, 0.65, -0.7};
  const VulkanBinding vk{ctx().instance(), ctx().physical_device(), ctx().device(), ctx().queue_family(), 0};
  AppDevice dev(vk);
  ASSERT_NO_THROW(dev.enable_gpu_composition(40, 36));
  std::mt19937 rng(99);
  const std::array<std::uint8_t, 3> clear{30, 60, 90};
  TestImage a[2] = {{ctx(), 40, 36}, {ctx(), 40, 36}}, b[2] = {{ctx(), 40, 36}, {ctx(), 40, 36}};
  TestImage target[2] = {{ctx(), 40, 36}, {ctx(), 40, 36}};
  std::array<Pixels8, 2> app_a{random_app(rng, 40, 36, clear), random_app(rng, 40, 36, clear)};
  std::array<Pixels8, 2> app_b{random_app(rng, 40, 36, clear), random_app(rng, 40, 36, clear)};
  dev.write({a[0].get(), a[1].get(), b[0].get(), b[1].get()}, {&app_a[0], &app_a[1], &app_b[0], &app_b[1]});
  CompositionRule rule;
  rule.blend = layer_blend(0, {false, false});
  std::array<Pixels8, 2> traced;
  const auto jobs_on = [&](TestImage (&img)[2], const Geometry& g) {
    std::array<AppDevice::GpuEye, 2> jobs;
    for (std::size_t e = 0; e < 2; ++e)
      jobs[e] = {eye_of(g, traced[e], e), {img[e].get(), 0, {{0, 0}, {40, 36}}}, std::nullopt, target[e].get()};
    return jobs;
  };
  for (int frame = 0; frame < 3; ++frame) {
    SCOPED_TRACE("frame " + std::to_string(frame));
    const Geometry g{"turning", 40, 36, 40, 36, fov, fov, 2.0 * frame, 0.02};
    for (Pixels8& t : traced) t = random_scene(rng, 40, 36);
    const auto jobs = jobs_on(a, g);
    const std::vector<Pixels8> gpu_out = composite_on_gpu(dev, jobs, rule, g);
    for (std::size_t e = 0; e < 2; ++e) {
      EyeComposition c = jobs[e].composition;
      c.app = &app_a[e];
      const Pixels8 host = compose_eye(c, rule);
      const auto [exact, rounding, other] = differences(gpu_out[e], host);
      const std::size_t n = host.data.size() / 4;
      EXPECT_LE(double(other), g.boundary_fraction * double(n)) << "eye " << e << ": " << other << " of " << n;
      EXPECT_EQ(rounding, 0u) << "eye " << e;
      EXPECT_GT(exact, n * 9 / 10) << "eye " << e;
    }
  }
  AppDevice::GpuStats n = dev.gpu_stats();
  EXPECT_EQ(n.recordings, 1);
  EXPECT_EQ(n.descriptor_updates, 1);
  EXPECT_EQ(n.submissions, 3);

  // A pass submitted on images `a`, not waited for: acquiring `b` considers no pass, acquiring
  // a[0] that pass (waited for if still in flight), a[1] then none.
  const Geometry still{"still", 40, 36, 40, 36, fov, fov, 0.0, 0.0};
  const auto jobs = jobs_on(a, still);
  const int slot = write_slot(dev, jobs);
  dev.composite_gpu(slot, jobs, rule);
  dev.traced_slots()->retire(slot);
  const std::int64_t waits = dev.gpu_stats().acquire_waits;
  EXPECT_EQ(dev.finish_image(b[0].get()), 0);
  EXPECT_EQ(dev.finish_image(b[1].get()), 0);
  EXPECT_EQ(dev.gpu_stats().acquire_waits, waits) << "a pass on other images was waited for";
  EXPECT_EQ(dev.finish_image(a[0].get()), 1);
  EXPECT_EQ(dev.finish_image(a[1].get()), 0);  // that pass is known finished now
  EXPECT_LE(dev.gpu_stats().acquire_waits, waits + 1);

  // Other images: recorded once more; images forgotten (their swapchain destroyed) are
  // recorded afresh when they come back.
  composite_on_gpu(dev, jobs_on(b, still), rule, still);
  composite_on_gpu(dev, jobs_on(b, still), rule, still);
  EXPECT_EQ(dev.gpu_stats().recordings, 2);
  dev.forget_images({b[0].get(), b[1].get()});
  composite_on_gpu(dev, jobs_on(b, still), rule, still);
  composite_on_gpu(dev, jobs_on(a, still), rule, still);
  n = dev.gpu_stats();
  EXPECT_EQ(n.recordings, 3);
  EXPECT_EQ(n.descriptor_updates, 1);
}

// The hand-over without the host: the slots are memory of the application's device (a device
// of its own here, with VK_KHR_external_memory_fd, standing in for one the runtime created
// through the layer), exported and imported by the path tracer's device: another VkDevice of
// the same physical device, chosen by UUID, or the application's device itself, adopted
// (gpu::GivenDevice), as the layer runs where it has a queue there. SlotWriter encodes linear
// frames, extreme values included, as encode_scene does on the host and copies their depths;
// the application's composition pass reads what was written. Validated, no validation message.
void hand_over_through_shared_slots(bool on_app_device) {
  constexpr int W = 24, H = 20;
  const std::size_t px = std::size_t(W) * H;
  gpu::ContextOptions app_options;
  app_options.validation = true;
  app_options.external_memory_fd = true;
  std::unique_ptr<gpu::Context> app_ctx;
  try {
    app_ctx = std::make_unique<gpu::Context>(app_options);
  } catch (const core::InputError& e) {
    GTEST_SKIP() << "this device cannot share memory between devices: " << e.what();
  }
  gpu::Context& app = *app_ctx;
  VulkanBinding vk{app.instance(), app.physical_device(), app.device(), app.queue_family(), 0};
  {
    // Without the extension the slots are host-written, and say why.
    AppDevice host_written(vk);
    host_written.enable_gpu_composition(W, H);
    EXPECT_FALSE(host_written.shared_slots().has_value());
    EXPECT_NE(host_written.no_shared_slots().find("XR_KHR_vulkan_enable"), std::string::npos);
    EXPECT_NO_THROW(host_written.slot_colour(0, 0));
  }
  vk.added.no_external_memory.clear();  // the layer enabled the extension
  AppDevice dev(vk);
  ASSERT_NO_THROW(dev.enable_gpu_composition(W, H));
  std::optional<AppDevice::SharedSlots> shared = dev.shared_slots();
  ASSERT_TRUE(shared.has_value()) << dev.no_shared_slots();
  EXPECT_THROW(dev.slot_colour(0, 0), std::logic_error);  // nothing for the host to write
  close(shared->memory.fd);
  std::unique_ptr<gpu::Context> path_tracer;
  if (on_app_device) {
    // One thread here: the test's submissions never overlap on the one queue.
    gpu::GivenDevice given{app.instance(), app.physical_device(), app.device(), app.queue_family(), 0};
    given.instance_api_version = VK_API_VERSION_1_2;
    given.device_extensions = {VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME};
    path_tracer = std::make_unique<gpu::Context>(given);
  } else {
    gpu::ContextOptions layer_options;
    layer_options.validation = true;
    layer_options.device_uuid = shared->device_uuid;
    layer_options.external_memory_fd = true;
    path_tracer = std::make_unique<gpu::Context>(layer_options);
  }
  gpu::Context& layer_ctx = *path_tracer;
  EXPECT_EQ(layer_ctx.device() == app.device(), on_app_device);
  const int slots = dev.traced_slots()->slots();
  // What the slots hold, read on the layer's device through a second import of the memory.
  std::optional<AppDevice::SharedSlots> probe_memory = dev.shared_slots();
  ASSERT_TRUE(probe_memory.has_value());
  gpu::BufferDesc probe_desc{SlotLayout{W, H}.bytes(slots), gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal, "probe"};
  probe_desc.imported = probe_memory->memory;
  const gpu::Buffer probe(layer_ctx, probe_desc);

  std::mt19937 rng(7);
  std::uniform_real_distribution<float> radiance(0.0f, 4.0f), distance(0.1f, 50.0f);
  const float inf = std::numeric_limits<float>::infinity();
  const float extremes[] = {std::numeric_limits<float>::quiet_NaN(), inf, -inf, -1.0f, 0.0f, 1e-30f, 1e30f,
                            std::numeric_limits<float>::max(), 1.0f};
  TestImage app_img[2] = {{app, W, H}, {app, W, H}}, target[2] = {{app, W, H}, {app, W, H}};
  const core::Fov fov{-0.7, 0.6, 0.65, -0.7};
  const Geometry g{"same views", W, H, W, H, fov, fov, 0.0, 0.0};
  for (const PixelFormat fmt : {PixelFormat{false, true}, PixelFormat{true, false}}) {
    SCOPED_TRACE(std::string(fmt.bgra ? "BGRA" : "RGBA") + (fmt.srgb ? " sRGB" : " UNORM"));
    SlotWriter writer(layer_ctx, dev.shared_slots()->memory, {W, H}, slots, fmt);
    std::array<core::Image, 2> linear;
    std::array<std::vector<float>, 2> depth;
    std::array<gpu::Buffer, 2> screen_buf, depth_buf;
    for (std::size_t e = 0; e < 2; ++e) {
      linear[e] = core::Image(W, H);
      for (std::size_t i = 0; i < px; ++i)
        for (int c = 0; c < 3; ++c)
          linear[e].pixels[i][c] = i < 40 ? extremes[(i + std::size_t(c) + e) % std::size(extremes)] : radiance(rng);
      depth[e].resize(px);
      for (float& d : depth[e]) d = distance(rng);
      screen_buf[e] = gpu::Buffer(layer_ctx, {px * 16, gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal, "screen"});
      screen_buf[e].upload(linear[e].pixels);
      depth_buf[e] = gpu::Buffer(layer_ctx, {px * 4, gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal, "depth"});
      depth_buf[e].upload(depth[e]);
    }
    const int slot = dev.traced_slots()->claim();
    ASSERT_GE(slot, 0);
    writer.write({SlotWriter::Eye{&screen_buf[0], &depth_buf[0]}, SlotWriter::Eye{&screen_buf[1], &depth_buf[1]}}, slot);

    const std::vector<std::uint32_t> words = probe.download<std::uint32_t>();
    std::array<Pixels8, 2> traced;
    for (std::size_t e = 0; e < 2; ++e) {
      traced[e] = {W, H, std::vector<std::uint8_t>(px * 4)};
      std::memcpy(traced[e].data.data(), &words[SlotLayout{W, H}.colour_word(slot, int(e))], px * 4);
      const Pixels8 host = encode_scene(linear[e], fmt);
      const auto [exact, rounding, other] = differences(traced[e], host);
      EXPECT_EQ(other, 0u) << "eye " << e;
      EXPECT_LE(double(rounding), 0.01 * double(px)) << "eye " << e;  // float against double at a rounding edge
      EXPECT_EQ(std::memcmp(&words[SlotLayout{W, H}.depth_word(slot, int(e))], depth[e].data(), px * 4), 0)
          << "eye " << e << ": the depths differ";
    }
    // The application's device composites what the layer's device wrote.
    std::array<AppDevice::GpuEye, 2> jobs;
    for (std::size_t e = 0; e < 2; ++e)
      jobs[e] = {eye_of(g, traced[e], e), {app_img[e].get(), 0, {{0, 0}, {W, H}}}, std::nullopt, target[e].get()};
    CompositionRule rule;
    rule.mode = Composite::SceneOnly;
    rule.blend = layer_blend(0, fmt);
    dev.composite_gpu(slot, jobs, rule);
    dev.traced_slots()->retire(slot);
    dev.finish();
    const std::vector<Pixels8> out = dev.read({{target[0].get(), 0, {{0, 0}, {W, H}}}, {target[1].get(), 0, {{0, 0}, {W, H}}}});
    for (std::size_t e = 0; e < 2; ++e) EXPECT_EQ(out[e].data, compose_eye(jobs[e].composition, rule).data) << "eye " << e;
  }
  EXPECT_EQ(app.validation_errors(), 0);
  EXPECT_EQ(layer_ctx.validation_errors(), 0);
}

TEST_F(GpuComposite, SharedSlotsHandTheFrameOverWithoutTheHost) { hand_over_through_shared_slots(false); }
TEST_F(GpuComposite, SlotsHandTheFrameOverOnTheApplicationsDevice) { hand_over_through_shared_slots(true); }

}  // namespace
}  // namespace fovea::layer
