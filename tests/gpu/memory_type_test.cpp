// Which memory type each gpu::Memory kind takes (gpu::memory_properties through
// find_memory_type) on the memory types real devices list: a discrete GPU with and without
// host-visible device memory (its BAR) and a CPU device. Per-frame uploads that every shader
// invocation reads (gpu::Memory::Upload) go to device memory where the device can map it, so
// a discrete GPU's shaders do not read them, nor run atomics on them, across the bus;
// readback stays in cached host memory. (Buffers.RoundTripEveryMemoryKind uses each kind on
// the test's device.)
#include <cstdint>
#include <initializer_list>
#include <optional>

#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/memory_type.hpp"

namespace gpu = fovea::gpu;

namespace {

constexpr VkMemoryPropertyFlags kLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
constexpr VkMemoryPropertyFlags kMapped = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
constexpr VkMemoryPropertyFlags kCached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;

VkPhysicalDeviceMemoryProperties types(std::initializer_list<VkMemoryPropertyFlags> flags) {
  VkPhysicalDeviceMemoryProperties p{};
  for (VkMemoryPropertyFlags f : flags) p.memoryTypes[p.memoryTypeCount++].propertyFlags = f;
  return p;
}

std::optional<std::uint32_t> pick(const VkPhysicalDeviceMemoryProperties& p, gpu::Memory m,
                                  std::uint32_t type_bits = ~0u) {
  const gpu::MemoryProperties want = gpu::memory_properties(m);
  return gpu::find_memory_type(p, type_bits, want.required, want.preferred);
}

}  // namespace

TEST(MemoryKinds, PickTheirTypesOnDiscreteAndCpuDevices) {
  // A discrete GPU's list (types without properties, device memory, host memory uncached and
  // cached, then its BAR: device memory the host can map).
  const auto discrete = types({0, kLocal, kMapped, kMapped | kCached, kLocal | kMapped});
  EXPECT_EQ(pick(discrete, gpu::Memory::DeviceLocal), 1u);
  EXPECT_EQ(pick(discrete, gpu::Memory::HostVisible), 3u);
  EXPECT_EQ(pick(discrete, gpu::Memory::Upload), 4u);
  // A buffer that cannot live in the BAR type takes mapped host memory.
  EXPECT_EQ(pick(discrete, gpu::Memory::Upload, 0b01111u), 2u);
  // Without a BAR: host memory, the first mapped type.
  const auto no_bar = types({kLocal, kMapped | kCached, kMapped});
  EXPECT_EQ(pick(no_bar, gpu::Memory::Upload), 1u);
  EXPECT_EQ(pick(no_bar, gpu::Memory::HostVisible), 1u);
  EXPECT_EQ(pick(no_bar, gpu::Memory::DeviceLocal), 0u);
  // A CPU device (lavapipe): one type for everything.
  const auto cpu = types({kLocal | kMapped | kCached});
  for (const gpu::Memory m : {gpu::Memory::DeviceLocal, gpu::Memory::HostVisible, gpu::Memory::Upload})
    EXPECT_EQ(pick(cpu, m), 0u);
  // Nothing mapped: no type for the mapped kinds.
  const auto unmapped = types({kLocal});
  EXPECT_FALSE(pick(unmapped, gpu::Memory::Upload).has_value());
  EXPECT_FALSE(pick(unmapped, gpu::Memory::HostVisible).has_value());
}
