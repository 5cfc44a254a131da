#include "layer_queue.hpp"

namespace fovea::layer {

LayerQueueRequest request_layer_queue(const std::vector<VkQueueFamilyProperties>& families,
                                      const VkDeviceQueueCreateInfo* requested, std::uint32_t count) {
  LayerQueueRequest r;
  if (requested) r.infos.assign(requested, requested + count);
  const auto nf = std::uint32_t(families.size());
  // Per family: the application's unprotected request (its index in r.infos), and whether it
  // asks protected queues there.
  std::vector<int> request(nf, -1);
  std::vector<bool> protected_queues(nf, false);
  for (std::size_t i = 0; i < r.infos.size(); ++i) {
    const VkDeviceQueueCreateInfo& q = r.infos[i];
    if (q.queueFamilyIndex >= nf) continue;  // the driver answers that
    if (q.flags != 0) protected_queues[q.queueFamilyIndex] = true;
    else request[q.queueFamilyIndex] = int(i);
  }
  static const float kLowest = 0.0f;
  const auto compute = [&](std::uint32_t f) {
    return (families[f].queueFlags & VK_QUEUE_COMPUTE_BIT) != 0 && !protected_queues[f] && families[f].queueCount > 0;
  };
  for (std::uint32_t f = 0; f < nf; ++f)
    if (compute(f) && request[f] < 0) {
      VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
      q.queueFamilyIndex = f;
      q.queueCount = 1;
      q.pQueuePriorities = &kLowest;
      r.infos.push_back(q);
      r.queue = QueueIndex{f, 0};
      return r;
    }
  std::string taken;
  for (std::uint32_t f = 0; f < nf; ++f) {
    if (!compute(f)) continue;
    VkDeviceQueueCreateInfo& q = r.infos[std::size_t(request[f])];
    if (q.queueCount < families[f].queueCount) {
      std::vector<float>& p = r.priorities.emplace_back(q.pQueuePriorities, q.pQueuePriorities + q.queueCount);
      p.push_back(kLowest);
      r.queue = QueueIndex{f, q.queueCount};
      q.pQueuePriorities = p.data();
      ++q.queueCount;
      return r;
    }
    taken += (taken.empty() ? "" : ", ") + std::string("family ") + std::to_string(f) + ": " +
             std::to_string(q.queueCount) + " of " + std::to_string(families[f].queueCount);
  }
  r.no_queue = taken.empty() ? "the device has no compute-capable queue family the layer may add a queue of"
                             : "the application asks for every queue of the compute-capable families (" + taken + ")";
  return r;
}

}  // namespace fovea::layer
