#pragma once
// GPU timestamps for one submission: begin(), then stage("name") after each stage's
// commands; after submit_and_wait, read() gives each stage's start and end in ns
// relative to begin(). Queues without timestamps (timestampValidBits == 0) are
// reported by supported() == false; recording is then a no-op and read() is nullopt.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fovea/gpu/handle.hpp"

namespace fovea::gpu {

class Context;

struct StageTime {
  std::string name;
  std::int64_t start_ns = 0;  // since begin()
  std::int64_t end_ns = 0;
  std::int64_t duration_ns() const { return end_ns - start_ns; }
};

// Nanoseconds from tick `a` to tick `b` of a counter with `valid_bits` bits (wrapping at
// 2^valid_bits) at `period_ns` per tick.
std::int64_t ticks_to_ns(std::uint64_t a, std::uint64_t b, std::uint32_t valid_bits, double period_ns);

class GpuTimer {
 public:
  GpuTimer() = default;
  explicit GpuTimer(Context& ctx, std::uint32_t max_stages = 32);

  bool supported() const { return static_cast<bool>(pool_); }

  // Records: resets the queries and writes the start timestamp (and forgets earlier stages).
  void begin(VkCommandBuffer cmd);
  // Records: a timestamp once all earlier commands finished, closing stage `name`.
  // Throws std::length_error beyond max_stages.
  void stage(VkCommandBuffer cmd, std::string name);
  // After the submission completed: the stages in order, or nullopt when unsupported.
  // Keep the result in a variable: `for (auto& s : *timer.read())` would dangle.
  std::optional<std::vector<StageTime>> read() const;

 private:
  std::uint32_t valid_bits_ = 0;
  double period_ns_ = 0;
  std::uint32_t max_stages_ = 0;
  bool begun_ = false;
  std::vector<std::string> names_;
  DeviceHandle<VkQueryPool, vkDestroyQueryPool> pool_;
};

}  // namespace fovea::gpu
