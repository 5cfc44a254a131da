// The one-shot submission on a device the caller does not own, run here on the test's own
// validated device standing in for an application's.
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <gtest/gtest.h>

#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/foreign_queue.hpp"
#include "gpu_fixture.hpp"

namespace fovea::gpu {
namespace {

using ForeignQueueTest = test::GpuTest;

std::uint32_t word(const gpu::Buffer& b, std::size_t i) {
  std::uint32_t v;
  std::memcpy(&v, b.mapped().data() + i * 4, 4);
  return v;
}

// Fills the buffer with `value`, made visible to the host once the submission completes.
void fill(VkCommandBuffer cb, const gpu::Buffer& buf, std::uint32_t value) {
  vkCmdFillBuffer(cb, buf.handle(), 0, buf.size(), value);
  VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0,
                       nullptr);
}

TEST_F(ForeignQueueTest, RunsRecordedCommandsToCompletion) {
  gpu::Buffer buf(ctx(), {64, gpu::BufferUsage::Storage, gpu::Memory::HostVisible, "foreign queue test"});
  std::memset(buf.mapped().data(), 0, 64);
  ForeignQueue q(ctx().device(), &vkGetDeviceProcAddr, ctx().queue_family(), ctx().queue(), 10'000'000'000,
                 "the test device");
  for (std::uint32_t value : {0xabcd1234u, 7u}) {  // the command buffer and fence are reused
    q.run([&](VkCommandBuffer cb) { fill(cb, buf, value); });
    // Complete when run() returns: no wait of the caller's own.
    for (std::size_t i = 0; i < 16; ++i) ASSERT_EQ(word(buf, i), value) << i;
  }
}

TEST_F(ForeignQueueTest, AFailedRecordingLeavesTheQueueUsable) {
  gpu::Buffer buf(ctx(), {16, gpu::BufferUsage::Storage, gpu::Memory::HostVisible, "foreign queue test"});
  ForeignQueue q(ctx().device(), &vkGetDeviceProcAddr, ctx().queue_family(), ctx().queue(), ForeignQueue::kNoTimeout,
                 "the test device");
  EXPECT_THROW(q.run([](VkCommandBuffer) { throw std::runtime_error("recording failed"); }), std::runtime_error);
  q.run([&](VkCommandBuffer cb) { fill(cb, buf, 5u); });
  EXPECT_EQ(word(buf, 3), 5u);
}

TEST_F(ForeignQueueTest, SubmitReturnsAndTheNextUseWaits) {
  gpu::Buffer buf(ctx(), {16, gpu::BufferUsage::Storage, gpu::Memory::HostVisible, "foreign queue test"});
  {
    ForeignQueue q(ctx().device(), &vkGetDeviceProcAddr, ctx().queue_family(), ctx().queue(), 10'000'000'000,
                   "the test device");
    q.submit([&](VkCommandBuffer cb) { fill(cb, buf, 1u); });
    q.submit([&](VkCommandBuffer cb) { fill(cb, buf, 2u); });  // waits for the first
    q.wait();
    EXPECT_EQ(word(buf, 0), 2u);
    q.wait();  // nothing pending: returns
    q.submit([&](VkCommandBuffer cb) { fill(cb, buf, 3u); });
  }  // destroyed while pending: waits (validation would report a pending command buffer freed)
  EXPECT_EQ(word(buf, 1), 3u);
}

TEST(ForeignQueue, RefusesAMissingDeviceNamingIt) {
  try {
    ForeignQueue q(VK_NULL_HANDLE, &vkGetDeviceProcAddr, 0, VK_NULL_HANDLE, 0, "the application's device");
    FAIL() << "constructed without a device";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("the application's device"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fovea::gpu
