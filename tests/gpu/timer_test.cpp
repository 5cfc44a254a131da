#include <cstdint>
#include <vector>

#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/gpu/timer.hpp"
#include "gpu_fixture.hpp"

namespace gpu = fovea::gpu;
using fovea::test::GpuTest;

TEST(TicksToNs, MasksAndWraps) {
  EXPECT_EQ(gpu::ticks_to_ns(10, 30, 64, 1.0), 20);
  EXPECT_EQ(gpu::ticks_to_ns(10, 30, 64, 2.5), 50);
  // 36 valid bits: garbage above them is ignored, and a wrap between a and b is undone.
  const std::uint64_t top = 1ull << 36;
  EXPECT_EQ(gpu::ticks_to_ns(0xff00000000000005ull, 0x0a00000000000009ull, 36, 1.0), 4);
  EXPECT_EQ(gpu::ticks_to_ns(top - 3, 2, 36, 1.0), 5);
}

using Timer = GpuTest;

TEST_F(Timer, StagesAreOrderedAndNonNegative) {
  gpu::GpuTimer timer(ctx());
  if (!ctx().timestamps_supported()) {
    EXPECT_FALSE(timer.supported());
    EXPECT_FALSE(timer.read().has_value());
    GTEST_SKIP() << "the queue has no timestamps (timestampValidBits == 0)";
  }
  ASSERT_TRUE(timer.supported());
  struct Push {
    std::uint32_t count, offset;
  };
  gpu::ComputePipeline pipe(ctx(), {.shader = "test_gpu_fill.comp.spv",
                                    .sets = {{gpu::Binding::StorageBuffer, gpu::Binding::UniformBuffer}},
                                    .push_constant_bytes = sizeof(Push)});
  gpu::Buffer out(ctx(), {.size = 4096 * 4});
  gpu::Buffer params(ctx(), {.size = 4, .usage = gpu::BufferUsage::Uniform});
  gpu::DescriptorSet set(ctx(), pipe.set_layout(0));
  set.bind(0, out).bind(1, params);
  ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    timer.begin(cmd);
    gpu::fill_buffer(cmd, params, 0);
    timer.stage(cmd, "clear");
    gpu::transfer_to_compute(cmd);
    pipe.run(cmd, {&set}, Push{4096, 0}, 4096);
    timer.stage(cmd, "fill");
    gpu::compute_to_compute(cmd);
    pipe.run(cmd, {&set}, Push{4096, 1}, 4096);
    timer.stage(cmd, "fill again");
  });
  const auto stages = timer.read();
  ASSERT_TRUE(stages.has_value());
  ASSERT_EQ(stages->size(), 3u);
  EXPECT_EQ((*stages)[0].name, "clear");
  EXPECT_EQ((*stages)[2].name, "fill again");
  std::int64_t previous_end = 0;
  for (const gpu::StageTime& s : *stages) {
    EXPECT_GE(s.start_ns, 0) << s.name;
    EXPECT_EQ(s.start_ns, previous_end) << s.name << " starts where the previous stage ended";
    EXPECT_GE(s.end_ns, s.start_ns) << s.name;
    previous_end = s.end_ns;
  }
}

TEST_F(Timer, MisuseThrows) {
  gpu::GpuTimer timer(ctx(), 1);
  if (!timer.supported()) GTEST_SKIP() << "no timestamps";
  EXPECT_THROW(timer.read(), std::logic_error);
  ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    EXPECT_THROW(timer.stage(cmd, "early"), std::logic_error);
    timer.begin(cmd);
    timer.stage(cmd, "one");
    EXPECT_THROW(timer.stage(cmd, "two"), std::length_error);
  });
  EXPECT_EQ(timer.read()->size(), 1u);
}
