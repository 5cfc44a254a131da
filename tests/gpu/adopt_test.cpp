// gpu::Context on a device made elsewhere (an OpenXR application's): the fixture's own
// context stands in for the application, whose instance, device and queue the adopted
// context runs on without owning them; validation messages reach the owner's counters.
#include <cstdint>
#include <string>
#include <vector>

#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/buffer.hpp"
#include "gpu_fixture.hpp"

namespace gpu = fovea::gpu;
using fovea::test::GpuTest;

namespace {

gpu::GivenDevice given_of(const gpu::Context& owner) {
  gpu::GivenDevice g;
  g.instance = owner.instance();
  g.physical_device = owner.physical_device();
  g.device = owner.device();
  g.queue_family = owner.queue_family();
  g.instance_api_version = VK_API_VERSION_1_2;
  return g;
}

}  // namespace

using AdoptDevice = GpuTest;

TEST_F(AdoptDevice, RunsOnTheGivenDeviceAndLeavesItToItsOwner) {
  {
    gpu::Context adopted(given_of(ctx()));
    EXPECT_FALSE(adopted.owns_device());
    EXPECT_EQ(adopted.device(), ctx().device());
    EXPECT_EQ(adopted.info().name, ctx().info().name);
    gpu::Buffer b(adopted, {.size = 64 * 4, .name = "adopted"});
    adopted.submit_and_wait([&](VkCommandBuffer cmd) { gpu::fill_buffer(cmd, b, 0x3f800000u); });
    for (float v : b.download<float>()) ASSERT_EQ(v, 1.0f);
  }
  // The owner's device, queue and instance outlive the adopted context.
  gpu::Buffer after(ctx(), {.size = 16, .name = "owner after"});
  ctx().submit_and_wait([&](VkCommandBuffer cmd) { gpu::fill_buffer(cmd, after, 7u); });
  EXPECT_EQ(after.download<std::uint32_t>(), (std::vector<std::uint32_t>{7, 7, 7, 7}));
}

TEST_F(AdoptDevice, SaysExactlyWhatTheGivenDeviceLacks) {
  gpu::GivenDevice g = given_of(ctx());
  g.instance_api_version = VK_API_VERSION_1_0;
  g.queue_family = 99;
  g.ray_query_features = true;  // without the extensions
  const std::vector<std::string> missing = gpu::missing_for_pipeline(g);
  ASSERT_EQ(missing.size(), 5u);
  EXPECT_EQ(missing[0], "Vulkan 1.2 on the instance (it was created for 1.0)");
  EXPECT_EQ(missing[1].rfind("queue family 99 (the device has ", 0), 0u) << missing[1];
  EXPECT_EQ(missing[2], "ray queries: VK_KHR_acceleration_structure enabled on the device");
  try {
    gpu::Context adopted(g);
    ADD_FAILURE() << "a device lacking what the pipeline needs was adopted";
  } catch (const fovea::core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("cannot run the pipeline; it lacks:\n  Vulkan 1.2 on the instance"), std::string::npos) << what;
  }
  EXPECT_TRUE(gpu::missing_for_pipeline(given_of(ctx())).empty());
  gpu::GivenDevice none;
  EXPECT_EQ(gpu::missing_for_pipeline(none).size(), 1u);
  // The owner's device is untouched by the refusals.
  gpu::Buffer b(ctx(), {.size = 16, .name = "owner"});
  ctx().submit_and_wait([&](VkCommandBuffer cmd) { gpu::fill_buffer(cmd, b, 1u); });
}
