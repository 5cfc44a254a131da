#pragma once
// What every reader of recorded gaze (readers.cpp, the HID capture replay in hid_stream.cpp)
// tells the user the same way: one policy, one wording.
#include <cstdint>
#include <string>

#include "fovea/core/view.hpp"
#include "fovea/devices/readers.hpp"

namespace fovea::devices::detail {

// Appends a note unless ReadStats::kMaxNotes are held.
void add_note(ReadStats& st, std::string what);
// "PATH: the gzip stream ends early (truncated file); the samples up to the cut were read"
std::string truncated_note(const std::string& path);

// Samples whose gaze lies outside the view its 2-D coordinates (or directions) refer to:
// rendered as tracked and clamped to the border, so a wrong screen geometry would go unseen.
// A sample counts when any tracked eye (or the combined gaze) points outside the frustum,
// behind the viewer included.
class OffViewCount {
 public:
  void add(const core::View& view, const GazeSample& s);
  // "PATH: N of M samples lie outside the display (WxH px); check the screen geometry" when
  // N > 0, for a raster of w × h pixels; then starts over.
  void note(ReadStats& st, const std::string& path, double w, double h);
  void reset() { outside_ = samples_ = 0; }

 private:
  std::uint64_t outside_ = 0, samples_ = 0;
};

}  // namespace fovea::devices::detail
