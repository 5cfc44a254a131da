#pragma once
// A queue of the application's VkDevice for the layer's path tracer, asked for when the
// runtime creates that device through the layer (XR_KHR_vulkan_enable2's
// xrCreateVulkanDeviceKHR, vulkan_enable.cpp): with a queue of its own the path tracer runs on
// the application's device without ever blocking the application's queue. A pure function of
// the physical device's queue families and the queues the application asks for.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace fovea::layer {

struct QueueIndex {
  std::uint32_t family = 0;
  std::uint32_t index = 0;
  bool operator==(const QueueIndex&) const = default;
};

struct LayerQueueRequest {
  // The application's queue requests with the layer's added (pass these to vkCreateDevice).
  std::vector<VkDeviceQueueCreateInfo> infos;
  std::optional<QueueIndex> queue;  // the layer's, when one could be added
  std::string no_queue;             // else why not
  // Storage for the priorities of an extended request.
  std::deque<std::vector<float>> priorities;
};

// The application's `requested` queues and, where the device has a queue to spare, one more
// for the layer, at the lowest priority (the application's queues come first where the
// device honours priorities). A compute-capable family the application does not use comes
// first (on discrete GPUs an asynchronous compute family, which runs beside the
// application's graphics); else a compute-capable family it uses, with a queue beyond those it
// asked for. Families the application asks protected queues of are left alone.
LayerQueueRequest request_layer_queue(const std::vector<VkQueueFamilyProperties>& families,
                                      const VkDeviceQueueCreateInfo* requested, std::uint32_t count);

}  // namespace fovea::layer
