#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/error.hpp"
#include "fovea/gpu/image.hpp"
#include "gpu_fixture.hpp"

namespace gpu = fovea::gpu;
using fovea::test::GpuTest;

namespace {

std::vector<std::uint32_t> iota_words(std::size_t n, std::uint32_t first) {
  std::vector<std::uint32_t> v(n);
  std::iota(v.begin(), v.end(), first);
  return v;
}

}  // namespace

using Buffers = GpuTest;

TEST_F(Buffers, RoundTripEveryMemoryKind) {
  for (gpu::Memory memory : {gpu::Memory::DeviceLocal, gpu::Memory::HostVisible, gpu::Memory::Upload}) {
    gpu::Buffer b(ctx(), {.size = 1000 * 4, .memory = memory, .name = "round trip"});
    EXPECT_EQ(b.host_visible(), memory != gpu::Memory::DeviceLocal);
    const auto data = iota_words(1000, 7);
    b.upload(data);
    EXPECT_EQ(b.download<std::uint32_t>(), data);

    // Partial transfers at an offset touch only their range.
    const std::vector<std::uint32_t> patch = {1, 2, 3};
    b.upload(patch, 40);
    std::vector<std::uint32_t> window(5);
    b.download(std::span(window), 36);
    EXPECT_EQ(window, (std::vector<std::uint32_t>{16, 1, 2, 3, 20}));
  }
}

TEST_F(Buffers, RejectsOutOfRangeAndEmpty) {
  gpu::Buffer b(ctx(), {.size = 16});
  const std::vector<std::uint32_t> five(5);
  EXPECT_THROW(b.upload(five), std::out_of_range);
  std::vector<std::uint32_t> out(2);
  EXPECT_THROW(b.download(std::span(out), 12), std::out_of_range);
  EXPECT_THROW(gpu::Buffer(ctx(), {.size = 0, .name = "empty"}), fovea::core::InputError);
}

TEST_F(Buffers, CopyAndFillOnTheGpu) {
  gpu::Buffer a(ctx(), {.size = 64});
  gpu::Buffer b(ctx(), {.size = 64, .memory = gpu::Memory::HostVisible});
  ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    gpu::fill_buffer(cmd, a, 0xabcd1234u);
    gpu::barrier(cmd, gpu::access::transfer_write, gpu::access::transfer_read);
    gpu::copy_buffer(cmd, a, b);
  });
  EXPECT_EQ(b.download<std::uint32_t>(), std::vector<std::uint32_t>(16, 0xabcd1234u));
}

TEST_F(Buffers, MoveTransfersOwnership) {
  gpu::Buffer a(ctx(), {.size = 16, .memory = gpu::Memory::HostVisible});
  const VkBuffer handle = a.handle();
  gpu::Buffer b = std::move(a);
  EXPECT_EQ(b.handle(), handle);
  EXPECT_EQ(a.handle(), VK_NULL_HANDLE);  // NOLINT(bugprone-use-after-move): checking the moved-from state
  EXPECT_FALSE(a.host_visible());
  EXPECT_EQ(a.size(), 0u);
  a = std::move(b);
  EXPECT_EQ(a.handle(), handle);
  EXPECT_TRUE(a.host_visible());
  a = gpu::Buffer(ctx(), {.size = 32});  // releases the first buffer
  EXPECT_EQ(a.size(), 32u);
}

TEST_F(Buffers, TexelFormatsAreCheckedAndBoundToTexelBindingsOnly) {
  const gpu::Buffer texels(ctx(), {.size = 64, .name = "texels", .texel_format = VK_FORMAT_R32G32B32A32_UINT});
  EXPECT_NE(texels.texel_view(), VK_NULL_HANDLE);
  const gpu::Buffer plain(ctx(), {.size = 64, .name = "plain"});
  EXPECT_EQ(plain.texel_view(), VK_NULL_HANDLE);
  const auto message = [](auto&& f) {
    try {
      f();
    } catch (const fovea::core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { gpu::Buffer(ctx(), {.size = 64, .name = "bytes", .texel_format = VK_FORMAT_R8_UNORM}); })
                .find("'bytes': texel format"),
            std::string::npos);
  const gpu::DescriptorSetLayout layout(ctx(), {gpu::Binding::StorageBuffer, gpu::Binding::TexelBuffer});
  gpu::DescriptorSet set(ctx(), layout);
  set.bind(0, texels).bind(1, texels);  // a buffer with a view serves both kinds of binding
  EXPECT_NE(message([&] { set.bind(1, plain); }).find("binding 1 is a texel buffer, and the buffer has no texel format"),
            std::string::npos);
  EXPECT_NE(message([&] { set.bind(1, texels, 16); }).find("binds its whole buffer"), std::string::npos);
}

using Images = GpuTest;

TEST_F(Images, RoundTripRgba32f) {
  gpu::Image2D img(ctx(), {.width = 13, .height = 7, .format = VK_FORMAT_R32G32B32A32_SFLOAT, .name = "rgba32f"});
  std::vector<glm::vec4> texels(13 * 7);
  for (std::size_t i = 0; i < texels.size(); ++i) texels[i] = {float(i), -0.5f * float(i), 1e-3f, 1e6f};
  img.upload(texels);
  EXPECT_EQ(img.download<glm::vec4>(), texels);
}

TEST_F(Images, RoundTripR32uiAndRgba8) {
  for (VkFormat format : {VK_FORMAT_R32_UINT, VK_FORMAT_R8G8B8A8_UNORM}) {
    gpu::Image2D img(ctx(), {.width = 5, .height = 3, .format = format});
    EXPECT_EQ(img.byte_size(), 5u * 3u * 4u);
    const auto texels = iota_words(15, 0xfedcba00u);
    img.upload(texels);
    EXPECT_EQ(img.download<std::uint32_t>(), texels);
  }
}

TEST_F(Images, RejectsBadSizesAndFormats) {
  EXPECT_THROW(gpu::Image2D(ctx(), {.width = 0, .height = 4}), fovea::core::InputError);
  EXPECT_THROW(gpu::Image2D(ctx(), {.width = 4, .height = 4, .format = VK_FORMAT_D32_SFLOAT}),
               fovea::core::InputError);
  gpu::Image2D img(ctx(), {.width = 4, .height = 4});
  const std::vector<glm::vec4> too_few(3);
  EXPECT_THROW(img.upload(too_few), std::invalid_argument);
}

TEST_F(Buffers, SubmissionsNest) {
  gpu::Buffer a(ctx(), {.size = 16});
  gpu::Buffer b(ctx(), {.size = 16, .memory = gpu::Memory::HostVisible});
  const auto data = iota_words(4, 9);
  ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    a.upload(data);  // its own submission, complete before the outer one is submitted
    gpu::copy_buffer(cmd, a, b);
  });
  EXPECT_EQ(b.download<std::uint32_t>(), data);
}

// A size the device cannot hold is the input's size (a display's raster, a scene): an
// InputError naming what, its size and the heap, not a VulkanError after the fact.
TEST(AllocationLimits, OutOfMemoryAndOversizedRequestsAreInputErrorsStatingTheLimit) {
  const VkDeviceSize mib = 1u << 20;
  try {
    gpu::check_fits(VK_SUCCESS, "vkAllocateMemory", "gpu::Buffer 'cells'", 3000 * mib, 2048 * mib);
    ADD_FAILURE() << "a request above the heap passed";
  } catch (const fovea::core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("gpu::Buffer 'cells': 3000 MiB, more than the device's memory heap holds 2048 MiB"),
              std::string::npos) << what;
  }
  try {
    gpu::check_fits(VK_ERROR_OUT_OF_DEVICE_MEMORY, "vkCreateBuffer", "gpu::Buffer 'cells'", 5 * mib, 0);
    ADD_FAILURE() << "an out-of-memory result passed";
  } catch (const fovea::core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("5 MiB: vkCreateBuffer ran out of memory (VK_ERROR_OUT_OF_DEVICE_MEMORY)"), std::string::npos)
        << what;
  }
  EXPECT_THROW(gpu::check_fits(VK_ERROR_DEVICE_LOST, "vkAllocateMemory", "b", mib, 2 * mib), gpu::VulkanError);
  EXPECT_NO_THROW(gpu::check_fits(VK_SUCCESS, "vkAllocateMemory", "b", mib, mib));
}

// Buffers charge their memory to the context while they live; a request past the limit the
// device can give (on a CPU device: 3/4 of the host memory available) is refused before
// anything is allocated, naming the sizes.
TEST_F(Buffers, DeviceMemoryIsChargedAndTheLimitRefusedBeforeAllocating) {
  gpu::Buffer probe(ctx(), {.size = 16, .name = "probe"});
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(ctx().device(), probe.handle(), &req);
  const std::uint32_t type = ctx().memory_type(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  const VkDeviceSize before = ctx().memory_in_use(type);
  {
    gpu::Buffer big(ctx(), {.size = 1u << 20, .name = "big"});
    EXPECT_GE(ctx().memory_in_use(type), before + (1u << 20));
    gpu::Buffer moved = std::move(big);  // the charge moves with it, once
    EXPECT_GE(ctx().memory_in_use(type), before + (1u << 20));
    EXPECT_LT(ctx().memory_in_use(type), before + (2u << 20));
  }
  EXPECT_EQ(ctx().memory_in_use(type), before);
  // Per heap: held now, and the most held at once (a refused charge is not counted in it).
  const auto heap_of = [&] {
    for (const auto& h : ctx().heap_use())
      if (h.size == ctx().memory_type_heap_size(type)) return h;
    ADD_FAILURE() << "no heap of memory type " << type;
    return gpu::Context::HeapUse{};
  };
  EXPECT_EQ(heap_of().held, before);
  EXPECT_GE(heap_of().peak, before + (1u << 20));
  ctx().reset_memory_peaks();
  EXPECT_EQ(heap_of().peak, before);
  const VkDeviceSize limit = ctx().memory_limit(type);
  EXPECT_LE(limit, ctx().memory_type_heap_size(type));
  try {
    [[maybe_unused]] gpu::MemoryCharge c = ctx().charge_memory("gpu::Buffer 'huge'", limit, type);
    ADD_FAILURE() << "a charge past the limit passed";
  } catch (const fovea::core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("gpu::Buffer 'huge'"), std::string::npos) << what;
    EXPECT_NE(what.find("more than this device can give"), std::string::npos) << what;
  }
  EXPECT_EQ(ctx().memory_in_use(type), before);
  EXPECT_EQ(heap_of().peak, before);
}
