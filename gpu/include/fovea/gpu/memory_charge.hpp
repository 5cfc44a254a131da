#pragma once
#include <atomic>
#include <cstdint>

namespace fovea::gpu {

// Device memory held by one buffer or image, charged to its Context's account while it
// lives (Context::charge_memory); moves carry the charge, destruction returns it.
class MemoryCharge {
 public:
  MemoryCharge() = default;
  MemoryCharge(std::atomic<std::uint64_t>* account, std::uint64_t bytes) : account_(account), bytes_(bytes) {}
  MemoryCharge(MemoryCharge&& o) noexcept : account_(o.account_), bytes_(o.bytes_) { o.account_ = nullptr; }
  MemoryCharge& operator=(MemoryCharge&& o) noexcept {
    if (this != &o) {
      release();
      account_ = o.account_, bytes_ = o.bytes_;
      o.account_ = nullptr;
    }
    return *this;
  }
  ~MemoryCharge() { release(); }

 private:
  void release() {
    if (account_) account_->fetch_sub(bytes_);
    account_ = nullptr;
  }
  std::atomic<std::uint64_t>* account_ = nullptr;
  std::uint64_t bytes_ = 0;
};

}  // namespace fovea::gpu
