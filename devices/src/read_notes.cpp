#include "read_notes.hpp"

#include <cmath>

namespace fovea::devices::detail {

void add_note(ReadStats& st, std::string what) {
  if (st.notes.size() < ReadStats::kMaxNotes) st.notes.push_back(std::move(what));
}

std::string truncated_note(const std::string& path) {
  return path + ": the gzip stream ends early (truncated file); the samples up to the cut were read";
}

void OffViewCount::add(const core::View& view, const GazeSample& s) {
  ++samples_;
  // A thousandth of a pixel of slack: a coordinate on the border maps back to it up to rounding.
  constexpr double kSlack = 1e-3;
  for (const EyeGaze* g : {&s.combined, &s.left, &s.right}) {
    if (!g->tracked()) continue;
    const auto px = view.dir_to_pixel(g->dir);
    if (!px || !(px->x >= -kSlack && px->y >= -kSlack && px->x <= view.width() + kSlack &&
                 px->y <= view.height() + kSlack)) {
      ++outside_;
      return;
    }
  }
}

void OffViewCount::note(ReadStats& st, const std::string& path, double w, double h) {
  if (outside_ > 0)
    add_note(st, path + ": " + std::to_string(outside_) + " of " + std::to_string(samples_) +
                     " samples lie outside the display (" + std::to_string(std::lround(w)) + "x" +
                     std::to_string(std::lround(h)) + " px); check the screen geometry");
  reset();
}

}  // namespace fovea::devices::detail
