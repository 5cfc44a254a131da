#pragma once
// Memory-type selection, for Fovea's own device and for devices it is handed (the
// application's, in the layer and the runtime).
#include <cstdint>
#include <optional>

#include <vulkan/vulkan_core.h>

namespace fovea::gpu {

// The first memory type allowed by `type_bits` that has all of `required` and all of
// `preferred`; failing that, the first with all of `required`; none: nullopt.
std::optional<std::uint32_t> find_memory_type(const VkPhysicalDeviceMemoryProperties& memory, std::uint32_t type_bits,
                                              VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred = 0);

}  // namespace fovea::gpu
