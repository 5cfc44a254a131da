// The layer's GPU composition (xr_layer_composite.comp through AppDevice::composite_gpu) on
// the test's validated device, standing in for the application's, against the host path
// (compose_eye) on the same inputs: random traced frames and application images with a
// background colour, opaque, translucent and transparent pixels, for every mode and blend.
#include <algorithm>
#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app_device.hpp"
#include "composite.hpp"
#include "gpu_fixture.hpp"

namespace fovea::layer {
namespace {

// A colour image the way a runtime hands out swapchain images: device-local, transfer
// source and destination, colour attachment.
class TestImage {
 public:
  TestImage(gpu::Context& ctx, int w, int h) : device_(ctx.device()) {
    VkImageCreateInfo ci{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ci.imageType = VK_IMAGE_TYPE_2D;
    ci.format = VK_FORMAT_R8G8B8A8_UNORM;
    ci.extent = {std::uint32_t(w), std::uint32_t(h), 1};
    ci.mipLevels = ci.arrayLayers = 1;
    ci.samples = VK_SAMPLE_COUNT_1_BIT;
    ci.tiling = VK_IMAGE_TILING_OPTIMAL;
    ci.usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
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
  ASSERT_NO_THROW(dev.enable_gpu_composition());
  std::mt19937 rng(1234);
  std::int64_t traced_id = 0;
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
        EyeComposition c;
        c.traced = &traced[e];
        c.traced_view = core::View(g.traced_fov, g.traced_w, g.traced_h);
        c.out_view = core::View(g.app_fov, g.traced_w, g.traced_h);
        c.to_traced = yaw(e == 0 ? g.yaw_deg : -g.yaw_deg);
        c.app_view = core::View(g.app_fov, g.app_w, g.app_h);
        jobs[e] = {c, {app_img[e].get(), 0, {{0, 0}, {g.app_w, g.app_h}}}, target[e].get()};
        c.app = m.mode == Composite::SceneOnly ? nullptr : &app[e];
        host[e] = compose_eye(c, rule);
      }
      const std::int64_t readbacks = dev.host_readbacks();
      dev.composite_gpu(++traced_id, jobs, rule);
      dev.finish();
      EXPECT_EQ(dev.host_readbacks(), readbacks) << "the GPU path copied application images to the host";
      const std::vector<Pixels8> gpu_out =
          dev.read({{target[0].get(), 0, {{0, 0}, {g.traced_w, g.traced_h}}},
                    {target[1].get(), 0, {{0, 0}, {g.traced_w, g.traced_h}}}});
      for (std::size_t e = 0; e < 2; ++e) {
        ASSERT_EQ(gpu_out[e].data.size(), host[e].data.size());
        std::size_t exact = 0, rounding = 0, other = 0;
        for (std::size_t i = 0; i < host[e].data.size(); i += 4) {
          int worst = 0;
          for (int c = 0; c < 4; ++c) worst = std::max(worst, std::abs(int(gpu_out[e].data[i + std::size_t(c)]) -
                                                                     int(host[e].data[i + std::size_t(c)])));
          (worst == 0 ? exact : worst == 1 ? rounding : other)++;
        }
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

}  // namespace
}  // namespace fovea::layer
