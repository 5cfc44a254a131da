#include "traced_slots.hpp"

#include <stdexcept>
#include <string>

namespace fovea::layer {

SlotPool::SlotPool(int slots) : slots_(slots), free_(0), retired_(0) {
  if (slots < 1 || slots > kMaxSlots)
    throw std::invalid_argument("SlotPool: " + std::to_string(slots) + " slots (1 to " + std::to_string(kMaxSlots) + ")");
  free_.store((1u << slots) - 1u);
}

int SlotPool::claim() {
  for (;;) {
    std::uint32_t f = free_.load(std::memory_order_acquire);
    if (f & kStop) return -1;
    if (f == 0) {
      free_.wait(0, std::memory_order_acquire);  // until a release() or stop()
      continue;
    }
    const int s = __builtin_ctz(f);
    // Only the render thread claims, but release() may set other bits meanwhile.
    if (free_.compare_exchange_weak(f, f & ~(1u << s), std::memory_order_acquire)) return s;
  }
}

void SlotPool::retire(int s) { retired_.fetch_or(1u << s, std::memory_order_acq_rel); }

std::uint32_t SlotPool::take_retired() { return retired_.exchange(0, std::memory_order_acq_rel); }

void SlotPool::release(int s) {
  // Release order: the composition passes that read the slot finished before the render
  // thread writes it again (their fences were seen signalled on this thread).
  free_.fetch_or(1u << s, std::memory_order_release);
  free_.notify_one();
}

void SlotPool::stop() {
  free_.fetch_or(kStop, std::memory_order_release);
  free_.notify_all();
}

}  // namespace fovea::layer
