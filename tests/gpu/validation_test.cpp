#include <cstdint>
#include <memory>

#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/image.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/gpu/timer.hpp"
#include "gpu_fixture.hpp"

namespace gpu = fovea::gpu;
using fovea::test::GpuTest;

using Validation = GpuTest;

TEST_F(Validation, CounterCatchesAnInvalidCall) {
  // A zero-sized buffer is invalid (VUID-VkBufferCreateInfo-size-00912); the layer
  // reports it and does not pass the call to the driver.
  expect_validation_errors(1, [&] {
    VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = 0;
    ci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBuffer b = VK_NULL_HANDLE;
    if (vkCreateBuffer(ctx().device(), &ci, nullptr, &b) == VK_SUCCESS) vkDestroyBuffer(ctx().device(), b, nullptr);
  });
}

namespace {

// Creates one of every resource kind, uses them in a submission, destroys them.
void exercise(gpu::Context& ctx) {
  struct Push {
    std::uint32_t count, offset;
  };
  gpu::ComputePipeline pipe(ctx, {.shader = "test_gpu_fill.comp.spv",
                                  .sets = {{gpu::Binding::StorageBuffer, gpu::Binding::UniformBuffer}},
                                  .push_constant_bytes = sizeof(Push)});
  gpu::Buffer out(ctx, {.size = 256});
  gpu::Buffer params(ctx, {.size = 4, .usage = gpu::BufferUsage::Uniform, .memory = gpu::Memory::HostVisible});
  gpu::Image2D img(ctx, {.width = 4, .height = 4, .sampled = true});
  gpu::Sampler sampler(ctx);
  gpu::GpuTimer timer(ctx);
  gpu::DescriptorSet set(ctx, pipe.set_layout(0));
  set.bind(0, out).bind(1, params);
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    timer.begin(cmd);
    pipe.run(cmd, {&set}, Push{64, 0}, 64);
    timer.stage(cmd, "fill");
  });
  out.download<std::uint32_t>();
}

}  // namespace

TEST(ValidationLifetime, DeviceDestructionIsClean) {
  std::shared_ptr<const gpu::ValidationCounters> counters;
  {
    gpu::Context ctx({.validation = true});
    counters = ctx.validation_counters();
    exercise(ctx);
  }
  EXPECT_EQ(counters->errors.load(), 0) << "validation errors, including at vkDestroyDevice";
  EXPECT_EQ(counters->warnings.load(), 0);
}

TEST(ValidationLifetime, LeakedObjectIsReportedAtDeviceDestruction) {
  std::shared_ptr<const gpu::ValidationCounters> counters;
  {
    gpu::Context ctx({.validation = true});
    counters = ctx.validation_counters();
    VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = 64;
    ci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBuffer leaked = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateBuffer(ctx.device(), &ci, nullptr, &leaked), VK_SUCCESS);
    EXPECT_EQ(counters->errors.load(), 0);
  }
  EXPECT_GE(counters->errors.load(), 1) << "the layer reports the buffer leaked at vkDestroyDevice";
}
