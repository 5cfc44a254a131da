#include "fovea/core/eye_optics.hpp"

#include <algorithm>
#include <atomic>
#include <thread>

namespace fovea::core {

ViewMask::ViewMask(const HiddenAreaMask& hidden)
    : width_(hidden.lens().view().width()),
      height_(hidden.lens().view().height()),
      words_per_row_((width_ + 31) / 32),
      bits_(std::size_t(words_per_row_) * std::size_t(height_), 0u) {
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
