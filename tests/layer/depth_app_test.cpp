// Depth compositing end to end: an application enabling XR_KHR_composition_layer_depth
// submits a solid magenta colour image per eye and chains a depth image whose left half is
// very near (0.12 m: in front of every Cornell box surface) and whose right half is far (5 m:
// behind the box's back wall, 0.8 m away). With the layer path tracing the Cornell box, the
// runtime's panels (lens off) must show magenta on the left and the scene on the right.
// Variants: D32_SFLOAT and D16_UNORM with the usual mapping, D32_SFLOAT with reversed Z.
// A recording layer below the Fovea layer checks what goes down: the application's other
// next-chain structures kept, its depth dropped, and (reversed-Z variant, which destroys the
// instance with its session alive) the layer's swapchains destroyed before the instance.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <chrono>
#include <fstream>
#include <thread>
#include <ostream>
#include <string>

#include "fovea/core/image.hpp"
#include "xr_fixture.hpp"
#include "xr_process.hpp"

namespace fovea::test {
namespace {

struct DepthVariant {
  std::string name;
  VkFormat format;
  bool reversed;  // nearZ > farZ: window depth 0 is far
};

void PrintTo(const DepthVariant& v, std::ostream* os) { *os << v.name; }

constexpr float kNear = 0.05f, kFar = 100.0f;
constexpr double kAppNear = 0.12, kAppFar = 5.0;
constexpr int kFrames = 3;

constexpr const char* kVariables[] = {"XR_API_LAYER_PATH", "XR_ENABLE_API_LAYERS", "FOVEA_LAYER_OUT",
                                      "FOVEA_LAYER_LOG_FILE", "FOVEA_SCENE", "FOVEA_LAYER_SCENE",
                                      "XDG_CONFIG_HOME", "FOVEA_RUNTIME_OUT", "FOVEA_RUNTIME_PNG_EVERY",
                                      "FOVEA_RUNTIME_LENS", "FOVEA_TEST_RECORD", "FOVEA_LAYER_RENDER"};

// Occurrences of `what` in `text`.
int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto i = text.find(what); i != std::string::npos; i = text.find(what, i + 1)) ++n;
  return n;
}

class DepthApp : public XrTest, public ::testing::WithParamInterface<DepthVariant> {
 protected:
  // The layer opens its log file once per process: one file for the suite.
  static void SetUpTestSuite() { log_dir_ = std::make_unique<TempDir>("depth-log"); }
  static void TearDownTestSuite() { log_dir_.reset(); }
  static std::string log_path() { return log_dir_->path() + "/layer.log"; }

  void SetUp() override {
    XrTest::SetUp();  // the tiny display
    out_ = std::make_unique<TempDir>("depth");
    setenv("FOVEA_RUNTIME_OUT", out_->path().c_str(), 1);
    setenv("FOVEA_RUNTIME_PNG_EVERY", "1", 1);
    setenv("FOVEA_RUNTIME_LENS", "off", 1);  // panels in the views' raster
    setenv("XDG_CONFIG_HOME", (out_->path() + "/no-config").c_str(), 1);
    setenv("XR_API_LAYER_PATH", FOVEA_LAYER_EXPLICIT_DIR ":" FOVEA_TEST_RECORDER_DIR, 1);
    setenv("XR_ENABLE_API_LAYERS", "XR_APILAYER_FOVEA_path_tracing:XR_APILAYER_FOVEA_test_recorder", 1);
    setenv("FOVEA_TEST_RECORD", (out_->path() + "/record.txt").c_str(), 1);
    setenv("FOVEA_LAYER_OUT", out_->path().c_str(), 1);
    setenv("FOVEA_LAYER_LOG_FILE", log_path().c_str(), 1);
    setenv("FOVEA_SCENE", "cornell", 1);
    // Each frame shows the path-traced frame of its own views: the composite is checked per frame.
    setenv("FOVEA_LAYER_RENDER", "lockstep", 1);
    unsetenv("FOVEA_LAYER_SCENE");
  }

  void TearDown() override {
    for (XrSwapchain sc : colour_) if (sc) xrDestroySwapchain(sc);
    for (XrSwapchain sc : depth_) if (sc) xrDestroySwapchain(sc);
    if (buffer_) vkDestroyBuffer(vk_device_, buffer_, nullptr);
    if (memory_) vkFreeMemory(vk_device_, memory_, nullptr);
    if (pool_) vkDestroyCommandPool(vk_device_, pool_, nullptr);
    XrTest::TearDown();
    for (const char* k : kVariables) unsetenv(k);
  }

  XrSwapchain swapchain(VkFormat format, XrSwapchainUsageFlags usage) {
    XrSwapchainCreateInfo ci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
    ci.usageFlags = usage | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
    ci.format = format;
    ci.sampleCount = 1;
    ci.width = width_;
    ci.height = height_;
    ci.faceCount = ci.arraySize = ci.mipCount = 1;
    XrSwapchain sc = XR_NULL_HANDLE;
    EXPECT_EQ(xrCreateSwapchain(session_, &ci, &sc), XR_SUCCESS);
    return sc;
  }

  // The window depth of view distance z under this variant's range (1/z affine in depth).
  float window_depth(double z) const {
    const double n = GetParam().reversed ? kFar : kNear, f = GetParam().reversed ? kNear : kFar;
    return float((1 / n - 1 / z) / (1 / n - 1 / f));
  }

  // A host-visible staging buffer with the colour image followed by the depth image.
  void make_staging() {
    const std::size_t texels = std::size_t(width_) * height_;
    const std::size_t depth_bytes = GetParam().format == VK_FORMAT_D16_UNORM ? 2 : 4;
    depth_offset_ = texels * 4;
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = depth_offset_ + texels * depth_bytes;
    bi.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    ASSERT_EQ(vkCreateBuffer(vk_device_, &bi, nullptr, &buffer_), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(vk_device_, buffer_, &req);
    VkPhysicalDeviceMemoryProperties mp;
    vkGetPhysicalDeviceMemoryProperties(vk_physical_, &mp);
    const VkMemoryPropertyFlags want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = ~0u;
    for (uint32_t i = 0; i < mp.memoryTypeCount && ai.memoryTypeIndex == ~0u; ++i)
      if ((req.memoryTypeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & want) == want) ai.memoryTypeIndex = i;
    ASSERT_NE(ai.memoryTypeIndex, ~0u);
    ASSERT_EQ(vkAllocateMemory(vk_device_, &ai, nullptr, &memory_), VK_SUCCESS);
    ASSERT_EQ(vkBindBufferMemory(vk_device_, buffer_, memory_, 0), VK_SUCCESS);
    void* mapped = nullptr;
    ASSERT_EQ(vkMapMemory(vk_device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped), VK_SUCCESS);
    auto* bytes = static_cast<std::uint8_t*>(mapped);
    const std::uint8_t magenta[4] = {255, 0, 255, 255};
    for (std::size_t i = 0; i < texels; ++i) std::memcpy(bytes + i * 4, magenta, 4);
    const float near_d = window_depth(kAppNear), far_d = window_depth(kAppFar);
    for (uint32_t y = 0; y < height_; ++y)
      for (uint32_t x = 0; x < width_; ++x) {
        const float d = x < width_ / 2 ? near_d : far_d;
        std::uint8_t* p = bytes + depth_offset_ + (std::size_t(y) * width_ + x) * depth_bytes;
        if (depth_bytes == 2) {
          const auto v = std::uint16_t(std::lround(double(d) * 65535.0));
          std::memcpy(p, &v, 2);
        } else {
          std::memcpy(p, &d, 4);
        }
      }
    vkUnmapMemory(vk_device_, memory_);
    VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = queue_family_;
    ASSERT_EQ(vkCreateCommandPool(vk_device_, &pi, nullptr, &pool_), VK_SUCCESS);
    VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cai.commandPool = pool_;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    ASSERT_EQ(vkAllocateCommandBuffers(vk_device_, &cai, &cmd_), VK_SUCCESS);
    vkGetDeviceQueue(vk_device_, queue_family_, 0, &queue_);
  }

  std::vector<VkImage> images(XrSwapchain sc) {
    uint32_t n = 0;
    EXPECT_EQ(xrEnumerateSwapchainImages(sc, 0, &n, nullptr), XR_SUCCESS);
    std::vector<XrSwapchainImageVulkanKHR> imgs(n, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR});
    EXPECT_EQ(xrEnumerateSwapchainImages(sc, n, &n, reinterpret_cast<XrSwapchainImageBaseHeader*>(imgs.data())),
              XR_SUCCESS);
    std::vector<VkImage> out;
    for (const auto& i : imgs) out.push_back(i.image);
    return out;
  }

  // Copies the staging buffer into `image` (left in `layout`, as the swapchain hands it over).
  void upload(VkImage image, bool depth) {
    const VkImageLayout layout =
        depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    const VkImageAspectFlags aspect = depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
    ASSERT_EQ(vkResetCommandBuffer(cmd_, 0), VK_SUCCESS);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    ASSERT_EQ(vkBeginCommandBuffer(cmd_, &bi), VK_SUCCESS);
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.oldLayout = layout;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    VkBufferImageCopy c{};
    c.bufferOffset = depth ? depth_offset_ : 0;
    c.imageSubresource = {aspect, 0, 0, 1};
    c.imageExtent = {width_, height_, 1};
    vkCmdCopyBufferToImage(cmd_, buffer_, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &c);
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = layout;
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT;
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    ASSERT_EQ(vkEndCommandBuffer(cmd_), VK_SUCCESS);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd_;
    ASSERT_EQ(vkQueueSubmit(queue_, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
    ASSERT_EQ(vkQueueWaitIdle(queue_), VK_SUCCESS);
  }

  // Acquire, wait, fill with the pattern, release.
  void draw(XrSwapchain sc, bool depth) {
    uint32_t index = 0;
    ASSERT_EQ(xrAcquireSwapchainImage(sc, nullptr, &index), XR_SUCCESS);
    XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
    wi.timeout = XR_INFINITE_DURATION;
    ASSERT_EQ(xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
    const std::vector<VkImage> imgs = images(sc);
    ASSERT_LT(index, imgs.size());
    ASSERT_NO_FATAL_FAILURE(upload(imgs[index], depth));
    ASSERT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
  }

  static inline std::unique_ptr<TempDir> log_dir_;
  std::unique_ptr<TempDir> out_;
  uint32_t width_ = 0, height_ = 0;
  XrSwapchain colour_[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
  XrSwapchain depth_[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize depth_offset_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
};

bool magenta(const glm::vec4& c) { return c.x > 0.95f && c.y < 0.05f && c.z > 0.95f; }

TEST_P(DepthApp, NearHalfShowsTheAppFarHalfShowsTheScene) {
  const int depth_sessions = count(read_text(log_path()), "compositing by depth");
  ASSERT_NO_FATAL_FAILURE(create_instance({XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME}));
  ASSERT_NO_FATAL_FAILURE(run_to_focused());
  const XrSpace local = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  XrViewConfigurationView vcv[2] = {{XR_TYPE_VIEW_CONFIGURATION_VIEW}, {XR_TYPE_VIEW_CONFIGURATION_VIEW}};
  uint32_t n = 0;
  ASSERT_EQ(xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 2, &n, vcv),
            XR_SUCCESS);
  width_ = vcv[0].recommendedImageRectWidth;
  height_ = vcv[0].recommendedImageRectHeight;
  for (int e = 0; e < 2; ++e) {
    colour_[e] = swapchain(VK_FORMAT_R8G8B8A8_SRGB, XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT);
    depth_[e] = swapchain(GetParam().format, XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
  }
  ASSERT_NO_FATAL_FAILURE(make_staging());

  XrCompositionLayerDepthInfoKHR depth[2];
  XrCompositionLayerProjectionView views[2];
  // Identity colour scale and bias (XR_KHR_composition_layer_color_scale_bias, not enabled: a
  // runtime ignores it) chained on the layer and before each view's depth.
  XrCompositionLayerColorScaleBiasKHR bias[3];
  for (auto& b : bias) {
    b = {XR_TYPE_COMPOSITION_LAYER_COLOR_SCALE_BIAS_KHR};
    b.colorScale = {1, 1, 1, 1};
  }
  for (int f = 0; f < kFrames; ++f) {
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    ASSERT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
    ASSERT_EQ(xrBeginFrame(session_, nullptr), XR_SUCCESS);
    XrViewLocateInfo li{XR_TYPE_VIEW_LOCATE_INFO};
    li.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    li.displayTime = fs.predictedDisplayTime;
    li.space = local;
    XrViewState vs{XR_TYPE_VIEW_STATE};
    XrView located[2] = {{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
    ASSERT_EQ(xrLocateViews(session_, &li, &vs, 2, &n, located), XR_SUCCESS);
    for (int e = 0; e < 2; ++e) {
      ASSERT_NO_FATAL_FAILURE(draw(colour_[e], false));
      ASSERT_NO_FATAL_FAILURE(draw(depth_[e], true));
      const XrRect2Di rect{{0, 0}, {int32_t(width_), int32_t(height_)}};
      depth[e] = {XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR};
      depth[e].subImage = {depth_[e], rect, 0};
      depth[e].minDepth = 0;
      depth[e].maxDepth = 1;
      depth[e].nearZ = GetParam().reversed ? kFar : kNear;
      depth[e].farZ = GetParam().reversed ? kNear : kFar;
      bias[e].next = &depth[e];
      views[e] = {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW, &bias[e]};
      views[e].pose = located[e].pose;
      views[e].fov = located[e].fov;
      views[e].subImage = {colour_[e], rect, 0};
    }
    XrCompositionLayerProjection proj{XR_TYPE_COMPOSITION_LAYER_PROJECTION, &bias[2]};
    proj.space = local;
    proj.viewCount = 2;
    proj.views = views;
    const XrCompositionLayerBaseHeader* layers[] = {reinterpret_cast<const XrCompositionLayerBaseHeader*>(&proj)};
    XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
    ei.displayTime = fs.predictedDisplayTime;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    ei.layerCount = 1;
    ei.layers = layers;
    ASSERT_EQ(xrEndFrame(session_, &ei), XR_SUCCESS);
  }

  const std::string log = read_text(log_path());
  EXPECT_EQ(count(log, "compositing by depth"), depth_sessions + 1) << log;
  EXPECT_EQ(log.find("internal failure"), std::string::npos) << log;
  // The log thread writes its records in batches (FrameLog::kFlushPeriod): wait for the last
  // frame's record rather than reading whatever was written so far. Records count the
  // session's xrEndFrame calls: run_to_focused's one (frame 0), then the kFrames above.
  std::string last;
  const std::string last_frame = "\"frame\":" + std::to_string(kFrames) + ",";
  for (int tries = 0; tries < 250 && last.find(last_frame) == std::string::npos; ++tries) {
    if (tries) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    std::ifstream timing(out_->path() + "/layer_timing.jsonl");
    for (std::string line; std::getline(timing, line);) last = line;
  }
  ASSERT_NE(last.find(last_frame), std::string::npos) << "the last frame's record was not written within 5 s: " << last;
  EXPECT_NE(last.find("\"replaced\":true"), std::string::npos) << last;
  // By depth on the application's device (the default compositor): no image reaches the host.
  EXPECT_NE(last.find("\"composited_on_gpu\":true,\"host_readbacks\":0"), std::string::npos) << last;

  // Below the layer: the replaced frame keeps the application's chains but the depth.
  const std::string bias_type = std::to_string(int(XR_TYPE_COMPOSITION_LAYER_COLOR_SCALE_BIAS_KHR));
  std::string record = read_text(out_->path() + "/record.txt");
  const auto last_end = record.rfind("end_frame");
  ASSERT_NE(last_end, std::string::npos) << record;
  EXPECT_EQ(record.substr(last_end, record.find('\n', last_end) - last_end),
            "end_frame projection=" + bias_type + " view=" + bias_type + " view=" + bias_type)
      << record;
  if (GetParam().reversed) {
    // The instance destroyed with its session and swapchains alive: the layer destroys its two
    // swapchains before the instance goes down, and nothing after it.
    const std::size_t before = record.size();
    ASSERT_EQ(xrDestroyInstance(instance_), XR_SUCCESS);
    instance_ = XR_NULL_HANDLE;
    session_ = XR_NULL_HANDLE;
    colour_[0] = colour_[1] = depth_[0] = depth_[1] = XR_NULL_HANDLE;
    record = read_text(out_->path() + "/record.txt").substr(before);
    EXPECT_EQ(count(record, "destroy_swapchain"), 2) << record;
    EXPECT_EQ(record.find("destroy_instance"), record.rfind('\n', record.size() - 2) + 1) << record;
  }

  // The last frame's panels: a block left of centre (the application's near half) and one
  // right of centre (its far half), both inside the lens's visible area.
  std::string latest;
  for (const auto& entry : std::filesystem::directory_iterator(out_->path())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("panel_", 0) == 0 && name.find("_left.png") != std::string::npos) latest = std::max(latest, name);
  }
  ASSERT_FALSE(latest.empty());
  for (const char* eye : {"left", "right"}) {
    const std::string file = latest.substr(0, latest.size() - std::strlen("left.png")) + eye + ".png";
    const core::Image panel = core::read_png(out_->path() + "/" + file, core::Encoding::Linear);
    ASSERT_EQ(panel.width, int(width_));
    int app_left = 0, app_right = 0, lit_right = 0, count = 0;
    for (int y = panel.height / 2 - 4; y < panel.height / 2 + 4; ++y)
      for (int dx = 0; dx < 6; ++dx, ++count) {
        app_left += magenta(panel.at(panel.width / 2 - 12 + dx, y));
        const glm::vec4 r = panel.at(panel.width / 2 + 6 + dx, y);
        app_right += magenta(r);
        lit_right += r.x + r.y + r.z > 0.01f;
      }
    EXPECT_EQ(app_left, count) << file << ": the application's near half";
    EXPECT_EQ(app_right, 0) << file << ": the application's far half lies behind the scene";
    EXPECT_EQ(lit_right, count) << file << ": the scene shows where the application is farther";
  }
}

INSTANTIATE_TEST_SUITE_P(Layer, DepthApp,
                         ::testing::Values(DepthVariant{"d32", VK_FORMAT_D32_SFLOAT, false},
                                           DepthVariant{"d16", VK_FORMAT_D16_UNORM, false},
                                           DepthVariant{"d32_reversed_z", VK_FORMAT_D32_SFLOAT, true}),
                         [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace fovea::test
