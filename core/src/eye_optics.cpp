#include "fovea/core/eye_optics.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <string>
#include <thread>

#include "fovea/core/error.hpp"

namespace fovea::core {

ViewMask::ViewMask(int width, int height)
    : width_(width),
      height_(height),
      words_per_row_((width_ + 31) / 32),
      bits_(std::size_t(words_per_row_) * std::size_t(height_), 0u) {}

ViewMask::ViewMask(const HiddenAreaMask& hidden) : ViewMask(hidden.lens().view().width(), hidden.lens().view().height()) {
  // Up to three inverse lens solves per pixel: rows are shared out over the cores (each
  // row's words belong to one thread).
  std::atomic<int> next_row{0};
  std::atomic<long> count{0};
  const auto work = [&] {
    long mine = 0;
    for (int y; (y = next_row++) < height_;)
      for (int x = 0; x < width_; ++x)
        if (!hidden.visible_view_px({x + 0.5, y + 0.5})) {
          bits_[std::size_t(y) * words_per_row_ + std::size_t(x >> 5)] |= 1u << (x & 31);
          ++mine;
        }
    count += mine;
  };
  const unsigned n = std::clamp(std::thread::hardware_concurrency(), 1u, 16u);
  std::vector<std::thread> pool;
  for (unsigned i = 1; i < n; ++i) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  hidden_fraction_ = double(count) / (double(width_) * height_);
}

ViewMask ViewMask::from_hidden_triangles(const View& view, std::span<const glm::vec2> vertices,
                                         std::span<const std::uint32_t> indices, const char* what) {
  if (indices.size() % 3)
    throw InputError(std::string(what) + ": " + std::to_string(indices.size()) + " indices, not whole triangles");
  ViewMask m(view.width(), view.height());
  // Tangent plane -> continuous pixel position (View::pixel_to_dir inverted).
  const double sx = view.width() / (view.tan_right() - view.tan_left());
  const double sy = view.height() / (view.tan_up() - view.tan_down());
  std::vector<glm::dvec2> px(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const glm::vec2 v = vertices[i];
    if (!std::isfinite(v.x) || !std::isfinite(v.y))
      throw InputError(std::string(what) + ": vertex " + std::to_string(i) + " is not finite");
    px[i] = {(v.x - view.tan_left()) * sx, (view.tan_up() - v.y) * sy};
  }
  for (std::size_t t = 0; t < indices.size(); t += 3) {
    glm::dvec2 p[3];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = indices[t + std::size_t(k)];
      if (i >= px.size())
        throw InputError(std::string(what) + ": index " + std::to_string(i) + " of triangle " + std::to_string(t / 3) +
                         " is beyond its " + std::to_string(px.size()) + " vertices");
      p[k] = px[i];
    }
    const auto edge = [](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
      return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    };
    const double area = edge(p[0], p[1], p[2]);
    if (area == 0) continue;  // degenerate: covers no pixel centre
    const double sign = area > 0 ? 1.0 : -1.0;
    // Pixel centres (x + 0.5) within the triangle's bounding box, clamped to the raster.
    const auto first = [](double lo) { return int(std::ceil(lo - 0.5)); };
    const auto last = [](double hi) { return int(std::floor(hi - 0.5)); };
    const int x0 = std::max(0, first(std::min({p[0].x, p[1].x, p[2].x})));
    const int x1 = std::min(m.width_ - 1, last(std::max({p[0].x, p[1].x, p[2].x})));
    const int y0 = std::max(0, first(std::min({p[0].y, p[1].y, p[2].y})));
    const int y1 = std::min(m.height_ - 1, last(std::max({p[0].y, p[1].y, p[2].y})));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const glm::dvec2 c{x + 0.5, y + 0.5};
        if (sign * edge(p[0], p[1], c) >= 0 && sign * edge(p[1], p[2], c) >= 0 && sign * edge(p[2], p[0], c) >= 0)
          m.bits_[std::size_t(y) * std::size_t(m.words_per_row_) + std::size_t(x >> 5)] |= 1u << (x & 31);
      }
  }
  long count = 0;
  for (const std::uint32_t w : m.bits_) count += std::popcount(w);
  m.hidden_fraction_ = double(count) / (double(m.width_) * m.height_);
  return m;
}

bool ViewMask::visible_at(glm::dvec2 px) const {
  if (bits_.empty()) return true;
  // The shader's index: the pixel containing px, clamped into the raster.
  const int x = int(std::clamp(px.x, 0.0, double(width_ - 1)));
  const int y = int(std::clamp(px.y, 0.0, double(height_ - 1)));
  return !hidden(x, y);
}

EyeOptics::EyeOptics(const Lens& lens) : hidden_(lens) {}

glm::dvec3 gaze_direction(const Lens& lens, glm::dvec2 panel_uv) {
  const glm::dvec2 t = lens.forward(panel_uv).tangent[1];
  return glm::normalize(glm::dvec3(t, -1.0));
}

std::optional<glm::dvec2> gaze_panel_uv(const Lens& lens, glm::dvec3 dir) {
  if (!(dir.z < 0)) return std::nullopt;
  const auto uv = lens.inverse(1, {dir.x / -dir.z, dir.y / -dir.z});
  if (!uv || uv->x < 0 || uv->y < 0 || uv->x > 1 || uv->y > 1) return std::nullopt;
  return uv;
}

}  // namespace fovea::core
