#include "frame_queue.hpp"

#include <iterator>

namespace fovea::layer {

void FrameQueue::waited(std::int64_t display_time_ns, std::int64_t call_ns, std::int64_t return_ns) {
  FrameTimes t;
  t.frame = next_frame_++;
  t.display_time_ns = display_time_ns;
  t.wait_call_ns = call_ns;
  t.wait_return_ns = return_ns;
  // A runtime predicting the same display time twice: the newer wait is the frame in flight.
  frames_[display_time_ns] = t;
  while (frames_.size() > kMaxInFlight) frames_.erase(frames_.begin());
}

void FrameQueue::begun(std::int64_t begin_ns) {
  for (auto& [time, t] : frames_)
    if (t.begin_ns == 0) {
      t.begin_ns = begin_ns;
      return;
    }
}

std::optional<FrameTimes> FrameQueue::end(std::int64_t display_time_ns) {
  auto it = frames_.find(display_time_ns);
  if (it == frames_.end() || it->second.begin_ns == 0) {
    it = frames_.begin();
    while (it != frames_.end() && it->second.begin_ns == 0) ++it;
  }
  if (it == frames_.end()) return std::nullopt;
  const FrameTimes ended = it->second;
  // Frames end in the order they began: an older begun frame was discarded by a later xrBeginFrame.
  for (auto old = frames_.begin(); old != it;) old = old->second.begin_ns != 0 ? frames_.erase(old) : std::next(old);
  frames_.erase(it);
  return ended;
}

}  // namespace fovea::layer
