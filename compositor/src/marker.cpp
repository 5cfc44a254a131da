#include "fovea/compositor/marker.hpp"

#include <algorithm>
#include <charconv>
#include <cstring>
#include <string>
#include <string_view>

#include "fovea/core/error.hpp"

namespace fovea::compositor {
namespace {

int parse_int(const char* name, const char* v, int lo, int hi, int fallback) {
  if (!v || !*v) return fallback;
  int x = 0;
  const char* end = v + std::strlen(v);
  const auto r = std::from_chars(v, end, x);
  if (r.ec != std::errc() || r.ptr != end || x < lo || x > hi)
    throw core::InputError(std::string(name) + "=" + v + ": expected an integer in " + std::to_string(lo) + ".." +
                           std::to_string(hi));
  return x;
}

}  // namespace

MarkerConfig marker_config(const char* (*get)(const char*)) {
  MarkerConfig c;
  if (const char* m = get("FOVEA_MARKER"); m && *m) {
    const std::string_view s(m);
    if (s == "off") c.mode = MarkerMode::Off;
    else if (s == "saccade") c.mode = MarkerMode::Saccade;
    else if (s == "periodic") c.mode = MarkerMode::Periodic;
    else throw core::InputError("FOVEA_MARKER=" + std::string(s) + ": expected off, saccade or periodic");
  }
  if (const char* k = get("FOVEA_MARKER_CORNER"); k && *k) {
    const std::string_view s(k);
    if (s == "tl") c.corner = MarkerCorner::TopLeft;
    else if (s == "tr") c.corner = MarkerCorner::TopRight;
    else if (s == "bl") c.corner = MarkerCorner::BottomLeft;
    else if (s == "br") c.corner = MarkerCorner::BottomRight;
    else throw core::InputError("FOVEA_MARKER_CORNER=" + std::string(s) + ": expected tl, tr, bl or br");
  }
  c.size_px = parse_int("FOVEA_MARKER_SIZE", get("FOVEA_MARKER_SIZE"), 1, 4096, c.size_px);
  c.frames = parse_int("FOVEA_MARKER_FRAMES", get("FOVEA_MARKER_FRAMES"), 1, 1000, c.frames);
  return c;
}

void draw_marker(core::Image& panel, MarkerCorner corner, int size_px, bool lit) {
  const int w = std::min(std::max(size_px, 0), panel.width), h = std::min(std::max(size_px, 0), panel.height);
  const bool right = corner == MarkerCorner::TopRight || corner == MarkerCorner::BottomRight;
  const bool bottom = corner == MarkerCorner::BottomLeft || corner == MarkerCorner::BottomRight;
  const int x0 = right ? panel.width - w : 0, y0 = bottom ? panel.height - h : 0;
  const glm::vec4 c = lit ? glm::vec4(1, 1, 1, 1) : glm::vec4(0, 0, 0, 1);
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x) panel.at(x, y) = c;
}

void MarkerSchedule::trigger(core::TimeNs sample_ns) {
  if (c_.mode != MarkerMode::Saccade || lit_left_ > 0 || pending_event_) return;
  pending_ = sample_ns;
  pending_event_ = true;
}

MarkerSchedule::Frame MarkerSchedule::next_frame() {
  Frame f;
  const std::int64_t index = frame_++;
  if (c_.mode == MarkerMode::Periodic && lit_left_ == 0 && index % (2 * std::int64_t(c_.frames)) == 0) {
    pending_event_ = true;
    pending_.reset();
  }
  if (pending_event_ && lit_left_ == 0) {
    lit_left_ = c_.frames;
    f.first = true;
    f.event_sample_ns = pending_;
    pending_event_ = false;
    pending_.reset();
  }
  if (lit_left_ > 0) {
    f.lit = true;
    --lit_left_;
  }
  return f;
}

}  // namespace fovea::compositor
