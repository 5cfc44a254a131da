// Physical-device choice, kept free of Vulkan calls so it can be tested on any machine.
#include <algorithm>
#include <cctype>
#include <string>

#include "fovea/core/error.hpp"
#include "fovea/gpu/context.hpp"

namespace fovea::gpu {
namespace {

std::string lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

const char* type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

// Higher is better: discrete > integrated > virtual > CPU > other.
int type_rank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 1;
    default: return 0;
  }
}

bool usable(const DeviceCandidate& c) { return c.api_version >= VK_API_VERSION_1_2 && c.has_compute_queue; }

std::string describe(std::span<const DeviceCandidate> candidates) {
  if (candidates.empty()) return "no Vulkan devices (is a Vulkan driver installed? VK_ICD_FILENAMES set?)";
  std::string s = "devices:";
  for (const DeviceCandidate& c : candidates) {
    s += "\n  '" + c.name + "' (" + type_name(c.type) + ", Vulkan " +
         std::to_string(VK_API_VERSION_MAJOR(c.api_version)) + "." +
         std::to_string(VK_API_VERSION_MINOR(c.api_version));
    if (c.api_version < VK_API_VERSION_1_2) s += ", unusable: Fovea needs Vulkan 1.2";
    if (!c.has_compute_queue) s += ", unusable: no compute queue";
    s += ")";
  }
  return s;
}

}  // namespace

std::size_t choose_device(std::span<const DeviceCandidate> candidates, std::string_view override) {
  if (!override.empty()) {
    const std::string want = lower(override);
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (lower(candidates[i].name).find(want) == std::string::npos) continue;
      if (!usable(candidates[i]))
        throw core::InputError("FOVEA_VK_DEVICE '" + std::string(override) + "' selects an unusable device; " +
                               describe(candidates));
      return i;
    }
    throw core::InputError("FOVEA_VK_DEVICE '" + std::string(override) + "' matches no Vulkan device; " +
                           describe(candidates));
  }
  std::size_t best = candidates.size();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (!usable(candidates[i])) continue;
    if (best == candidates.size() || type_rank(candidates[i].type) > type_rank(candidates[best].type)) best = i;
  }
  if (best == candidates.size())
    throw std::runtime_error("no usable Vulkan device (Vulkan 1.2 with a compute queue); " + describe(candidates));
  return best;
}

}  // namespace fovea::gpu
