// Which memory type each gpu::Memory kind takes (gpu::memory_properties through
// find_memory_type) on the memory types real devices list: a discrete GPU with and without
// host-visible device memory (its BAR) and a CPU device. Per-frame uploads that every shader
// invocation reads (gpu::Memory::Upload) go to device memory where the device can map it, so
// a discrete GPU's shaders do not read them, nor run atomics on them, across the bus;
// readback stays in cached host memory, and an upload whose device memory is full falls back
// to host memory. (Buffers.RoundTripEveryMemoryKind uses each kind on the test's device.)
#include <cstdint>
#include <initializer_list>
#include <optional>

#include <gtest/gtest.h>

#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/memory_type.hpp"

namespace gpu = fovea::gpu;

namespace {

constexpr VkMemoryPropertyFlags kLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
constexpr VkMemoryPropertyFlags kMapped = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
constexpr VkMemoryPropertyFlags kCached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;

// Memory types with these properties; a device-local type's heap is device memory, every
// other type's host memory (heaps 0 and 1).
VkPhysicalDeviceMemoryProperties types(std::initializer_list<VkMemoryPropertyFlags> flags) {
  VkPhysicalDeviceMemoryProperties p{};
  p.memoryHeapCount = 2;
  p.memoryHeaps[0].flags = VK_MEMORY_HEAP_DEVICE_LOCAL_BIT;
  for (VkMemoryPropertyFlags f : flags) {
    VkMemoryType& t = p.memoryTypes[p.memoryTypeCount++];
    t.propertyFlags = f;
    t.heapIndex = (f & kLocal) != 0 ? 0 : 1;
  }
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

TEST(MemoryKinds, AnUploadFallsBackToHostMemoryWhenDeviceMemoryIsFull) {
  const auto discrete = types({0, kLocal, kMapped, kMapped | kCached, kLocal | kMapped});
  EXPECT_EQ(gpu::upload_fallback_type(discrete, ~0u, 4), 3u);        // the BAR's: cached host memory
  EXPECT_EQ(gpu::upload_fallback_type(discrete, 0b10111u, 4), 2u);   // one the buffer can live in
  EXPECT_FALSE(gpu::upload_fallback_type(discrete, ~0u, 3).has_value());  // in host memory already
  EXPECT_FALSE(gpu::upload_fallback_type(discrete, ~0u, 9).has_value());  // no such type
  // A CPU device's one heap: nowhere else to go.
  VkPhysicalDeviceMemoryProperties cpu{};
  cpu.memoryHeapCount = 1;
  cpu.memoryHeaps[0].flags = VK_MEMORY_HEAP_DEVICE_LOCAL_BIT;
  cpu.memoryTypeCount = 1;
  cpu.memoryTypes[0].propertyFlags = kLocal | kMapped | kCached;
  EXPECT_FALSE(gpu::upload_fallback_type(cpu, ~0u, 0).has_value());
}
