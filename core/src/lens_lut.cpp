#include "fovea/core/lens_lut.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"

namespace fovea::core {

LensLut::LensLut(const Lens& lens, int size) : n_(size) {
  if (size < 2 || size > 4096)
    throw InputError("lens LUT: size must be in 2..4096, got " + std::to_string(size));
  uv_.resize(size_t(n_) * n_ * 3);
  const double cell = 1.0 / (n_ - 1);
  for (int c = 0; c < 3; ++c) {
    const Lens::Channel& ch = lens.channel(c);
    // Past the edge Lens::source_uv continues with the edge's radial scale, a kink that a
    // cell straddling the edge would smear over the visible pixels inside it. Nodes within
    // one cell beyond the edge hold the model's own smooth continuation instead (when
    // finite), so those cells interpolate the profile the visible pixels follow.
    const double reach = ch.r_edge + glm::length(glm::dvec2(cell) * ch.to_radial);
    for (int j = 0; j < n_; ++j)
      for (int i = 0; i < n_; ++i) {
        const glm::dvec2 uv(i * cell, j * cell);
        const glm::dvec2 t = (uv - ch.display_centre) * ch.to_radial;
        const double r = glm::length(t);
        glm::dvec2 v = lens.source_uv(c, uv);
        if (r > ch.r_edge && r <= reach) {
          const glm::dvec2 smooth = ch.source_centre + ch.from_radial * t * (lens.radial(c, r) / r);
          if (std::isfinite(smooth.x) && std::isfinite(smooth.y)) v = smooth;
        }
        uv_[(size_t(j) * n_ + i) * 3 + size_t(c)] = v;
      }
  }
}

glm::dvec2 LensLut::source_uv(int c, glm::dvec2 display_uv) const {
  const glm::dvec2 p = glm::clamp(display_uv, 0.0, 1.0) * double(n_ - 1);
  const glm::dvec2 i0 = glm::min(glm::floor(p), glm::dvec2(n_ - 2));
  const glm::dvec2 f = p - i0;
  const size_t i = size_t(i0.x), j = size_t(i0.y), n = size_t(n_);
  const auto node = [&](size_t x, size_t y) { return uv_[(y * n + x) * 3 + size_t(c)]; };
  const glm::dvec2 top = glm::mix(node(i, j), node(i + 1, j), f.x);
  const glm::dvec2 bottom = glm::mix(node(i, j + 1), node(i + 1, j + 1), f.x);
  return glm::mix(top, bottom, f.y);
}

std::vector<float> LensLut::packed() const {
  std::vector<float> out(uv_.size() * 2);
  for (size_t k = 0; k < uv_.size(); ++k) out[2 * k] = float(uv_[k].x), out[2 * k + 1] = float(uv_[k].y);
  return out;
}

std::array<LutError, 3> measure_lut_error(const LensLut& lut, const HiddenAreaMask& mask, int stride) {
  const Lens& lens = mask.lens();
  const int W = mask.width(), H = mask.height();
  const glm::dvec2 px(W, H);
  stride = std::max(stride, 1);
  std::array<LutError, 3> e{};
  std::array<long, 3> count{};
  for (int y = 0; y < H; y += stride)
    for (int x = 0; x < W; x += stride) {
      if (mask.hidden(x, y)) continue;
      const glm::dvec2 uv((x + 0.5) / W, (y + 0.5) / H);
      for (int c = 0; c < 3; ++c) {
        const glm::dvec2 cached = lut.source_uv(c, uv);
        const double view_px = glm::length((cached - lens.source_uv(c, uv)) * px);
        // The panel displacement that moves the direct source point onto the cached one:
        // J⁻¹·Δsource with J = ∂source_uv/∂display_uv (central differences; the error is
        // far below the scale on which J varies). The inverse optics cannot be used: near
        // the aperture the cached point may need a radius just beyond the edge.
        const glm::dvec2 delta = cached - lens.source_uv(c, uv);
        const double h = 1e-6;
        const glm::dvec2 ju = (lens.source_uv(c, uv + glm::dvec2(h, 0)) - lens.source_uv(c, uv - glm::dvec2(h, 0))) / (2 * h);
        const glm::dvec2 jv = (lens.source_uv(c, uv + glm::dvec2(0, h)) - lens.source_uv(c, uv - glm::dvec2(0, h))) / (2 * h);
        const double det = ju.x * jv.y - jv.x * ju.y;
        const glm::dvec2 shift = glm::dvec2(jv.y * delta.x - jv.x * delta.y, -ju.y * delta.x + ju.x * delta.y) / det;
        const double display_px = std::isfinite(det) && det != 0 ? glm::length(shift * px) : glm::length(px);
        LutError& le = e[size_t(c)];
        le.max_view_px = std::max(le.max_view_px, view_px);
        le.mean_view_px += view_px;
        if (display_px > le.max_display_px) le.max_display_px = display_px, le.worst_uv = uv;
        le.mean_display_px += display_px;
        ++count[size_t(c)];
      }
    }
  for (int c = 0; c < 3; ++c)
    if (count[size_t(c)] > 0) {
      e[size_t(c)].mean_view_px /= double(count[size_t(c)]);
      e[size_t(c)].mean_display_px /= double(count[size_t(c)]);
    }
  return e;
}

}  // namespace fovea::core
