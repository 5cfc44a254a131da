#pragma once
// Which of the slots for path-traced frames (in the application's device memory, read by the
// GPU composition pass) the render thread may write. Lock-free between the two threads: the
// render thread claims a free slot, writes its finished frame there and publishes it; a slot
// whose frame is gone (neither shown any more nor waiting to be) is retired, and the
// application's thread releases it once no pending composition pass reads it. Neither thread
// ever waits for the other on a lock: a render thread at nice 19 that loses its core
// between two atomic operations stalls nobody.
#include <atomic>
#include <cstdint>
#include <memory>

namespace fovea::layer {

class SlotPool {
 public:
  static constexpr int kMaxSlots = 16;
  explicit SlotPool(int slots);  // all free; throws std::invalid_argument outside 1..kMaxSlots

  int slots() const { return slots_; }
  // Render thread: a free slot, now its own; waits until the application's thread releases
  // one. -1 after stop().
  int claim();
  // Any thread: slot `s`'s frame is gone. It is not written again before release(s).
  void retire(int s);
  // Application thread: the slots retired since the last call (bit i: slot i).
  std::uint32_t take_retired();
  // Application thread: slot `s` (retired, read by no pending pass) may be written again.
  void release(int s);
  // Wakes a claim() waiting for a slot; claims fail from then on.
  void stop();

 private:
  static constexpr std::uint32_t kStop = 1u << 31;
  int slots_;
  std::atomic<std::uint32_t> free_;     // bit i: slot i free; kStop: stopping
  std::atomic<std::uint32_t> retired_;  // bit i: slot i retired, not yet released
};

// A path-traced frame's slot, held while the frame may be shown: retired when the frame goes.
class SlotLease {
 public:
  SlotLease(std::shared_ptr<SlotPool> pool, int slot) : pool_(std::move(pool)), slot_(slot) {}
  ~SlotLease() {
    if (pool_) pool_->retire(slot_);
  }
  SlotLease(const SlotLease&) = delete;
  SlotLease& operator=(const SlotLease&) = delete;
  int slot() const { return slot_; }

 private:
  std::shared_ptr<SlotPool> pool_;
  int slot_;
};

}  // namespace fovea::layer
