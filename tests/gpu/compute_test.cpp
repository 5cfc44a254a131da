#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include <glm/vec4.hpp>

#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/image.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "gpu_fixture.hpp"

namespace gpu = fovea::gpu;
using fovea::test::GpuTest;

namespace {

struct FillPush {  // test_gpu_fill.comp's push_constant block
  std::uint32_t count, offset;
};

gpu::ComputePipelineDesc fill_desc(std::vector<gpu::SpecConstant> spec) {
  return {.shader = "test_gpu_fill.comp.spv",
          .sets = {{gpu::Binding::StorageBuffer, gpu::Binding::UniformBuffer}},
          .push_constant_bytes = sizeof(FillPush),
          .specialization = std::move(spec)};
}

}  // namespace

using Compute = GpuTest;

TEST_F(Compute, DispatchWithPushAndSpecializationConstants) {
  // Workgroups of 32 (specialized) over 1000 threads: 32 groups, the last one partial.
  gpu::ComputePipeline pipe(ctx(), fill_desc({gpu::SpecConstant::u32(0, 3), gpu::SpecConstant::u32(1, 32)}));
  EXPECT_EQ(pipe.workgroup_size(), (std::array<std::uint32_t, 3>{32, 1, 1}));
  const std::uint32_t n = 1000, capacity = 1024;
  gpu::Buffer out(ctx(), {.size = capacity * 4, .name = "fill out"});
  gpu::Buffer params(ctx(), {.size = 4, .usage = gpu::BufferUsage::Uniform, .memory = gpu::Memory::HostVisible});
  params.upload(std::vector<std::uint32_t>{100000});
  gpu::DescriptorSet set(ctx(), pipe.set_layout(0));
  set.bind(0, out).bind(1, params);

  ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    gpu::fill_buffer(cmd, out, 0xffffffffu);
    gpu::transfer_to_compute(cmd);
    pipe.run(cmd, {&set}, FillPush{n, 5}, n);
  });
  const auto got = out.download<std::uint32_t>();
  for (std::uint32_t i = 0; i < capacity; ++i)
    ASSERT_EQ(got[i], i < n ? i * 3 + 5 + 100000 : 0xffffffffu) << "index " << i;
}

// A device compiles each description once (a pipeline takes ~15 ms to create on lavapipe, and
// a frame pipeline has 15): pipelines of one description share the kernel, and it outlives
// the pipeline that made it; another specialisation is another kernel; a description that
// failed fails again.
TEST_F(Compute, PipelinesOfOneDescriptionShareTheirKernel) {
  auto first = std::make_unique<gpu::ComputePipeline>(ctx(), fill_desc({gpu::SpecConstant::u32(0, 3)}));
  gpu::ComputePipeline same(ctx(), fill_desc({gpu::SpecConstant::u32(0, 3)}));
  const gpu::ComputePipeline other(ctx(), fill_desc({gpu::SpecConstant::u32(0, 4)}));
  EXPECT_EQ(first->handle(), same.handle());
  EXPECT_EQ(first->layout(), same.layout());
  EXPECT_EQ(first->set_layout(0).handle(), same.set_layout(0).handle());
  EXPECT_NE(first->handle(), other.handle());
  first.reset();

  const std::uint32_t n = 100;
  gpu::Buffer out(ctx(), {.size = n * 4, .name = "fill out"});
  gpu::Buffer params(ctx(), {.size = 4, .usage = gpu::BufferUsage::Uniform, .memory = gpu::Memory::HostVisible});
  params.upload(std::vector<std::uint32_t>{1000});
  gpu::DescriptorSet set(ctx(), same.set_layout(0));
  set.bind(0, out).bind(1, params);
  ctx().submit_and_wait([&](VkCommandBuffer cmd) { same.run(cmd, {&set}, FillPush{n, 7}, n); });
  const auto got = out.download<std::uint32_t>();
  for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(got[i], i * 3 + 7 + 1000) << "index " << i;

  const gpu::ComputePipelineDesc bad{.shader = "test_gpu_fill.comp.spv", .sets = {{gpu::Binding::StorageBuffer}}};
  EXPECT_THROW(gpu::ComputePipeline(ctx(), bad), fovea::core::InputError);
  EXPECT_THROW(gpu::ComputePipeline(ctx(), bad), fovea::core::InputError);
}

// More workgroups than the device allows in x (65535 on lavapipe): dispatch refuses them,
// dispatch_linear folds them into rows and every invocation index is covered once.
TEST_F(Compute, LinearDispatchFoldsMoreGroupsThanTheDeviceAllowsInX) {
  gpu::ComputePipeline pipe(ctx(), fill_desc({gpu::SpecConstant::u32(1, 1)}));  // groups of 1
  const std::uint32_t limit = ctx().limits().maxComputeWorkGroupCount[0];
  const std::uint32_t n = limit + 4321, capacity = n + 64;
  gpu::Buffer out(ctx(), {.size = std::uint64_t(capacity) * 4, .name = "fill out"});
  gpu::Buffer params(ctx(), {.size = 4, .usage = gpu::BufferUsage::Uniform, .memory = gpu::Memory::HostVisible});
  params.upload(std::vector<std::uint32_t>{7});
  gpu::DescriptorSet set(ctx(), pipe.set_layout(0));
  set.bind(0, out).bind(1, params);
  ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    EXPECT_THROW(pipe.run(cmd, {&set}, FillPush{n, 0}, n), fovea::core::InputError);
    gpu::fill_buffer(cmd, out, 0xffffffffu);
    gpu::transfer_to_compute(cmd);
    pipe.run_linear(cmd, {&set}, FillPush{n, 0}, n);
  });
  const auto got = out.download<std::uint32_t>();
  for (std::uint32_t i = 0; i < capacity; ++i)
    ASSERT_EQ(got[i], i < n ? i + 7 : 0xffffffffu) << "index " << i;
}

TEST_F(Compute, DefaultWorkgroupSizeAndChainedDispatches) {
  gpu::ComputePipeline pipe(ctx(), fill_desc({}));
  EXPECT_EQ(pipe.workgroup_size(), (std::array<std::uint32_t, 3>{64, 1, 1}));
  gpu::Buffer out(ctx(), {.size = 130 * 4});
  gpu::Buffer params(ctx(), {.size = 4, .usage = gpu::BufferUsage::Uniform, .memory = gpu::Memory::HostVisible});
  params.upload(std::vector<std::uint32_t>{0});
  gpu::DescriptorSet set(ctx(), pipe.set_layout(0));
  set.bind(0, out).bind(1, params);
  // Two writes of the same buffer: the barrier orders them (synchronization validation
  // would report a write-after-write hazard without it).
  ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    pipe.run(cmd, {&set}, FillPush{130, 1}, 130);
    gpu::compute_to_compute(cmd);
    pipe.run(cmd, {&set}, FillPush{65, 2}, 65);
  });
  const auto got = out.download<std::uint32_t>();
  for (std::uint32_t i = 0; i < 130; ++i) ASSERT_EQ(got[i], i + (i < 65 ? 2 : 1)) << i;
}

TEST_F(Compute, StorageAndSampledImages) {
  struct Push {
    std::uint32_t width, height, add;
  };
  gpu::ComputePipeline pipe(
      ctx(), {.shader = "test_gpu_image.comp.spv",
              .sets = {{gpu::Binding::StorageImage, gpu::Binding::SampledImage, gpu::Binding::StorageImage}},
              .push_constant_bytes = sizeof(Push)});
  const std::uint32_t w = 19, h = 11;
  gpu::Image2D src(ctx(), {.width = w, .height = h, .sampled = true, .name = "src"});
  gpu::Image2D dst(ctx(), {.width = w, .height = h, .format = VK_FORMAT_R32_UINT, .name = "dst"});
  gpu::Sampler sampler(ctx(), VK_FILTER_NEAREST);
  std::vector<glm::vec4> texels(w * h);
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) texels[y * w + x] = {float(x), float(y), 7.0f, 1.0f};
  src.upload(texels);
  gpu::DescriptorSet set(ctx(), pipe.set_layout(0));
  set.bind(0, src).bind(1, src, sampler).bind(2, dst);
  ctx().submit_and_wait([&](VkCommandBuffer cmd) { pipe.run(cmd, {&set}, Push{w, h, 40}, w, h); });
  const auto got = dst.download<std::uint32_t>();
  for (std::uint32_t y = 0; y < h; ++y)
    for (std::uint32_t x = 0; x < w; ++x) ASSERT_EQ(got[y * w + x], x + 1000 * y + 7 + 40) << x << "," << y;
}

TEST_F(Compute, MisuseIsReportedBeforeVulkanSeesIt) {
  try {
    gpu::ComputePipeline p(ctx(), {.shader = "nope.comp.spv"});
    FAIL() << "expected InputError";
  } catch (const fovea::core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test_gpu_fill.comp.spv"), std::string::npos) << "lists known shaders";
  }
  EXPECT_THROW(gpu::ComputePipeline{}.set_layout(0), std::out_of_range);  // an empty pipeline
  gpu::ComputePipeline pipe(ctx(), fill_desc({}));
  gpu::Buffer buf(ctx(), {.size = 4, .usage = gpu::BufferUsage::Storage | gpu::BufferUsage::Uniform});
  gpu::DescriptorSet set(ctx(), pipe.set_layout(0));
  EXPECT_THROW(set.bind(0, buf).bind(1, buf).bind(2, buf), fovea::core::InputError);
  gpu::Image2D img(ctx(), {.width = 1, .height = 1});
  EXPECT_THROW(set.bind(1, img), fovea::core::InputError);
  ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    EXPECT_THROW(pipe.push(cmd, std::uint32_t{1}), fovea::core::InputError);
    EXPECT_THROW(pipe.dispatch(cmd, 0xffffffffu, 0xffffffffu), fovea::core::InputError);
  });
}

// A layout that drifted from the shader's layout(binding = ...) declarations fails when the
// pipeline is created, naming the binding; so do slots that miss or repeat a binding.
TEST_F(Compute, BindingMismatchFailsAtStartUp) {
  const auto message = [&](std::vector<gpu::Binding> set) -> std::string {
    try {
      gpu::ComputePipeline p(ctx(), {.shader = "test_gpu_fill.comp.spv", .sets = {std::move(set)},
                                     .push_constant_bytes = sizeof(FillPush)});
    } catch (const fovea::core::InputError& e) {
      return e.what();
    }
    return "";
  };
  const auto S = gpu::Binding::StorageBuffer, U = gpu::Binding::UniformBuffer;
  EXPECT_NE(message({S, U, S}).find("binding 2"), std::string::npos) << "a binding the shader lacks";
  EXPECT_NE(message({S}).find("binding 1"), std::string::npos) << "a binding the layout lacks";
  EXPECT_NE(message({S, S}).find("binding 1 is a uniform buffer in the shader"), std::string::npos) << "type";
  EXPECT_EQ(message({S, U}), "");

  gpu::ComputePipeline pipe(ctx(), fill_desc({}));
  gpu::Buffer out(ctx(), {.size = 64 * 4});
  gpu::Buffer params(ctx(), {.size = 4, .usage = gpu::BufferUsage::Uniform});
  gpu::DescriptorSet set(ctx(), pipe.set_layout(0));
  const gpu::BufferSlot missing[] = {{0, &out}};
  const gpu::BufferSlot twice[] = {{0, &out}, {0, &out}, {1, &params}};
  const gpu::BufferSlot beyond[] = {{0, &out}, {1, &params}, {2, &out}};
  const gpu::BufferSlot all[] = {{1, &params}, {0, &out}};
  EXPECT_THROW(set.bind_all(missing), fovea::core::InputError);
  EXPECT_THROW(set.bind_all(twice), fovea::core::InputError);
  EXPECT_THROW(set.bind_all(beyond), fovea::core::InputError);
  EXPECT_NO_THROW(set.bind_all(all));
}

// Pipelines on a device through its own function table (as the layer and the runtime make
// them on the application's): one per specialisation, the layout checked against the shader
// like ComputePipeline's, nothing left behind by a failure or by destroy (the validation
// layer reports leaked objects when the device goes).
TEST_F(Compute, ForeignPipelinesFollowTheShader) {
  gpu::ForeignPipelineDesc desc{"test_gpu_fill.comp.spv",
                                {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC},
                                sizeof(FillPush),
                                {{3u, 32u}, {5u, 64u}}};
  gpu::ForeignPipelines p = gpu::create_foreign_pipelines(ctx().device(), &vkGetDeviceProcAddr, desc);
  ASSERT_EQ(p.pipelines.size(), 2u);
  EXPECT_NE(p.pipelines[0], p.pipelines[1]);
  EXPECT_NE(p.layout, VK_NULL_HANDLE);
  EXPECT_NE(p.set_layout, VK_NULL_HANDLE);
  gpu::destroy_foreign_pipelines(ctx().device(), &vkGetDeviceProcAddr, p);
  EXPECT_TRUE(p.pipelines.empty());
  EXPECT_EQ(p.layout, VK_NULL_HANDLE);

  desc.specializations.clear();
  p = gpu::create_foreign_pipelines(ctx().device(), &vkGetDeviceProcAddr, desc);
  EXPECT_EQ(p.pipelines.size(), 1u) << "no specialisation: one pipeline";
  gpu::destroy_foreign_pipelines(ctx().device(), &vkGetDeviceProcAddr, p);

  desc.bindings[1] = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  try {
    p = gpu::create_foreign_pipelines(ctx().device(), &vkGetDeviceProcAddr, desc);
    FAIL() << "expected InputError";
  } catch (const fovea::core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("binding 1 is a uniform buffer in the shader"), std::string::npos) << e.what();
  }
  desc.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  EXPECT_THROW(gpu::create_foreign_pipelines(ctx().device(), &vkGetDeviceProcAddr, desc), fovea::core::InputError);
}

// Synchronization validation is on: a dispatch writing a buffer right after a transfer
// wrote it, without a barrier, is reported. (This layer version does not flag
// dispatch-after-dispatch write hazards, so compute_to_compute must not be forgotten.)
TEST_F(Compute, MissingBarrierIsReported) {
  gpu::ComputePipeline pipe(ctx(), fill_desc({}));
  gpu::Buffer out(ctx(), {.size = 64 * 4});
  gpu::Buffer params(ctx(), {.size = 4, .usage = gpu::BufferUsage::Uniform, .memory = gpu::Memory::HostVisible});
  gpu::DescriptorSet set(ctx(), pipe.set_layout(0));
  set.bind(0, out).bind(1, params);
  expect_validation_errors(1, [&] {
    ctx().submit_and_wait([&](VkCommandBuffer cmd) {
      gpu::fill_buffer(cmd, out, 0);
      pipe.run(cmd, {&set}, FillPush{64, 2}, 64);
    });
  });
}
