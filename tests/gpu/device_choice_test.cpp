#include <cctype>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/gpu/context.hpp"

namespace gpu = fovea::gpu;
using fovea::core::InputError;

namespace {

std::vector<gpu::DeviceCandidate> three_devices() {
  return {{"llvmpipe (LLVM 15.0.6, 256 bits)", VK_PHYSICAL_DEVICE_TYPE_CPU, VK_API_VERSION_1_3, true},
          {"Intel(R) UHD Graphics 620", VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU, VK_API_VERSION_1_3, true},
          {"NVIDIA GeForce RTX 3080", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, VK_API_VERSION_1_3, true}};
}

// Sets an environment variable for one scope, restoring the previous value.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    had_ = std::getenv(name) != nullptr;
    setenv(name, value, 1);
  }
  ~ScopedEnv() {
    if (had_)
      setenv(name_, old_.c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

std::string message_of(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    return x.what();
  }
}

}  // namespace

TEST(ChooseDevice, PrefersDiscreteThenIntegratedThenVirtualThenCpu) {
  auto d = three_devices();
  EXPECT_EQ(gpu::choose_device(d, ""), 2u);
  d[2].api_version = VK_API_VERSION_1_1;  // a discrete GPU without Vulkan 1.2 is skipped
  EXPECT_EQ(gpu::choose_device(d, ""), 1u);
  d[1].type = VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU;
  EXPECT_EQ(gpu::choose_device(d, ""), 1u);
  d[1].has_compute_queue = false;
  EXPECT_EQ(gpu::choose_device(d, ""), 0u);
}

TEST(ChooseDevice, OverrideIsCaseInsensitiveSubstring) {
  const auto d = three_devices();
  EXPECT_EQ(gpu::choose_device(d, "LLVMPIPE"), 0u);
  EXPECT_EQ(gpu::choose_device(d, "uhd"), 1u);
  EXPECT_EQ(gpu::choose_device(d, "RTX"), 2u);
}

TEST(ChooseDevice, NoMatchOrUnusableMatchListsDevices) {
  auto d = three_devices();
  try {
    gpu::choose_device(d, "voodoo");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("voodoo"), std::string::npos) << m;
    EXPECT_NE(m.find("llvmpipe"), std::string::npos) << m;
    EXPECT_NE(m.find("RTX 3080"), std::string::npos) << m;
  }
  d[2].api_version = VK_API_VERSION_1_1;
  try {
    gpu::choose_device(d, "rtx");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("needs Vulkan 1.2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(gpu::choose_device({}, ""), std::runtime_error);
}

// The Context tests below run on whatever Vulkan device the machine has (lavapipe on the
// project's test machines, a GPU elsewhere): they name the device the default choice took.
namespace {
std::string default_device_name() {
  ScopedEnv no_override("FOVEA_VK_DEVICE", "");
  return gpu::Context({.validation = true}).info().name;
}
}  // namespace

// A CPU device only when there is nothing else; with a GPU present the default must be that GPU.
TEST(Context, DefaultChoiceIsBestDevice) {
  ScopedEnv no_override("FOVEA_VK_DEVICE", "");
  gpu::Context ctx({.validation = true});
  std::uint32_t n = 0;
  ASSERT_EQ(vkEnumeratePhysicalDevices(ctx.instance(), &n, nullptr), VK_SUCCESS);
  std::vector<VkPhysicalDevice> devices(n);
  ASSERT_EQ(vkEnumeratePhysicalDevices(ctx.instance(), &n, devices.data()), VK_SUCCESS);
  bool all_cpu = true;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    all_cpu = all_cpu && p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  }
  if (all_cpu) {
    EXPECT_EQ(ctx.info().type, VK_PHYSICAL_DEVICE_TYPE_CPU) << ctx.info().name;
  } else {
    EXPECT_NE(ctx.info().type, VK_PHYSICAL_DEVICE_TYPE_CPU) << ctx.info().name;
  }
  EXPECT_GE(ctx.info().api_version, VK_API_VERSION_1_2);
  EXPECT_TRUE(ctx.validation_enabled());
  EXPECT_EQ(ctx.validation_errors(), 0);
}

TEST(Context, EnvOverrideSelectsByCaseInsensitiveName) {
  const std::string name = default_device_name();
  std::string shouted = name;
  for (char& c : shouted) c = char(std::toupper(static_cast<unsigned char>(c)));
  ScopedEnv env("FOVEA_VK_DEVICE", shouted.c_str());
  gpu::Context ctx({.validation = true});
  EXPECT_EQ(ctx.info().name, name);
}

TEST(Context, NonsenseOverrideIsClearError) {
  const std::string name = default_device_name();
  ScopedEnv env("FOVEA_VK_DEVICE", "no-such-gpu-xyz");
  std::exception_ptr error;
  try {
    gpu::Context ctx({.validation = true});
  } catch (const InputError&) {
    error = std::current_exception();
  }
  ASSERT_TRUE(error) << "expected core::InputError";
  const std::string m = message_of(error);
  EXPECT_NE(m.find("FOVEA_VK_DEVICE 'no-such-gpu-xyz' matches no Vulkan device"), std::string::npos) << m;
  EXPECT_NE(m.find(name), std::string::npos) << "the message lists the devices: " << m;
}

TEST(Context, OptionOverridesEnvironment) {
  const std::string name = default_device_name();
  ScopedEnv env("FOVEA_VK_DEVICE", "no-such-gpu-xyz");
  gpu::Context ctx({.validation = true, .device = name});
  EXPECT_EQ(ctx.info().name, name);
}

TEST(Context, ValidationEnvironmentIsParsed) {
  {
    ScopedEnv env("FOVEA_VK_VALIDATION", "perhaps");
    EXPECT_THROW(gpu::Context ctx, InputError);
  }
  {
    ScopedEnv env("FOVEA_VK_VALIDATION", "0");
    gpu::Context ctx;
    EXPECT_FALSE(ctx.validation_enabled());
  }
  {
    ScopedEnv env("FOVEA_VK_VALIDATION", "1");
    gpu::Context ctx;
    EXPECT_TRUE(ctx.validation_enabled());
  }
}

TEST(Context, MissingValidationLayerIsClearError) {
  // The loader looks for explicit layers only in VK_LAYER_PATH when it is set.
  ScopedEnv env("VK_LAYER_PATH", "/nonexistent-fovea-layer-dir");
  try {
    gpu::Context ctx({.validation = true});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("VK_LAYER_KHRONOS_validation is not installed"), std::string::npos)
        << e.what();
  }
  gpu::Context without({.validation = false});  // validation off does not need the layer
  EXPECT_FALSE(without.validation_enabled());
}

// Logs the figures docs/gpu.md quotes; checks only what the Vulkan spec guarantees.
TEST(Context, ReportsDeviceInfo) {
  gpu::Context ctx({.validation = true});
  const gpu::DeviceInfo& i = ctx.info();
  std::printf("device: %s | driver: %s | Vulkan %u.%u\n", i.name.c_str(), i.driver.c_str(),
              VK_API_VERSION_MAJOR(i.api_version), VK_API_VERSION_MINOR(i.api_version));
  std::printf("subgroup %u, shared memory %u B, workgroup <= %u invocations (%u x %u x %u), push constants %u B\n",
              i.subgroup_size, i.max_shared_memory_bytes, i.max_workgroup_invocations, i.max_workgroup_size[0],
              i.max_workgroup_size[1], i.max_workgroup_size[2], i.max_push_constant_bytes);
  std::printf("timestamps: %u valid bits, %.3f ns/tick\n", i.timestamp_valid_bits, i.timestamp_period_ns);
  EXPECT_GT(i.subgroup_size, 0u);
  EXPECT_GE(i.max_shared_memory_bytes, 16384u);
  EXPECT_GE(i.max_workgroup_invocations, 128u);
  EXPECT_GE(i.max_push_constant_bytes, 128u);
  EXPECT_FALSE(i.driver.empty());
}
