#include "fovea/core/hidden_area.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace fovea::core {

bool shows_all_channels(const Lens& lens, glm::dvec2 uv) {
  const View& v = lens.view();
  const LensSample s = lens.forward(uv);
  if (!s.within_lens) return false;
  for (const glm::dvec2& t : s.tangent)
    if (!(t.x >= v.tan_left() && t.x <= v.tan_right() && t.y >= v.tan_down() && t.y <= v.tan_up())) return false;
  return true;
}

HiddenAreaMask::HiddenAreaMask(const Lens& lens) : lens_(lens) {
  const int W = width(), H = height();
  words_per_row_ = (W + 31) / 32;
  bits_.assign(size_t(words_per_row_) * H, 0u);
  size_t count = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (!shows_all_channels(lens_, {(x + 0.5) / W, (y + 0.5) / H})) {
        bits_[size_t(y) * words_per_row_ + (x >> 5)] |= 1u << (x & 31);
        ++count;
      }
    }
  hidden_fraction_ = double(count) / (double(W) * H);
}

bool HiddenAreaMask::hidden_at(glm::dvec2 px) const {
  if (!(px.x >= 0 && px.y >= 0 && px.x < width() && px.y < height())) return true;
  return hidden(int(px.x), int(px.y));
}

bool HiddenAreaMask::visible(glm::dvec3 d) const {
  if (!(d.z < 0)) return false;
  const glm::dvec2 t(d.x / -d.z, d.y / -d.z);
  const View& v = lens_.view();
  if (!(t.x >= v.tan_left() && t.x <= v.tan_right() && t.y >= v.tan_down() && t.y <= v.tan_up())) return false;
  for (int c = 0; c < 3; ++c) {
    const auto uv = lens_.inverse(c, t);
    if (uv && uv->x >= 0 && uv->y >= 0 && uv->x <= 1 && uv->y <= 1 && shows_all_channels(lens_, *uv)) return true;
  }
  return false;
}

bool HiddenAreaMask::visible_view_px(glm::dvec2 px) const {
  const glm::dvec2 t = lens_.uv_to_tangent(px / glm::dvec2(width(), height()));
  return visible(glm::dvec3(t, -1.0));
}

namespace {

// Distance from o (inside the rectangle) along unit u to the rectangle's border.
double to_border(glm::dvec2 o, glm::dvec2 u, glm::dvec2 lo, glm::dvec2 hi) {
  double s = std::numeric_limits<double>::infinity();
  if (u.x > 0) s = std::min(s, (hi.x - o.x) / u.x);
  if (u.x < 0) s = std::min(s, (lo.x - o.x) / u.x);
  if (u.y > 0) s = std::min(s, (hi.y - o.y) / u.y);
  if (u.y < 0) s = std::min(s, (lo.y - o.y) / u.y);
  return s;
}

double cross(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

}  // namespace

VisibilityMesh visibility_mesh(const HiddenAreaMask& mask, VisibilityMeshType type, int segments) {
  const Lens& lens = mask.lens();
  const View& v = lens.view();
  const glm::dvec2 lo(v.tan_left(), v.tan_down()), hi(v.tan_right(), v.tan_up());
  const glm::dvec2 corners[4] = {{lo.x, lo.y}, {hi.x, lo.y}, {hi.x, hi.y}, {lo.x, hi.y}};  // CCW
  const auto seen = [&](glm::dvec2 t) { return mask.visible(glm::dvec3(t, -1.0)); };
  // The optical axis (green channel's lens centre), kept strictly inside the rectangle.
  glm::dvec2 o = lens.uv_to_tangent(lens.channel(1).source_centre);
  o = glm::clamp(o, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo));

  VisibilityMesh m;
  if (!seen(o)) {  // nothing traceable: all hidden, no visible part
    if (type == VisibilityMeshType::HiddenTriangles) {
      for (const auto& c : corners) m.vertices.emplace_back(c);
      m.indices = {0, 1, 2, 0, 2, 3};
    }
    return m;
  }

  // Ray directions: uniform angles plus the four corners, so the outer ring follows the
  // rectangle exactly.
  std::vector<double> angles;
  segments = std::max(segments, 8);
  for (int i = 0; i < segments; ++i) angles.push_back(2 * std::numbers::pi * i / segments);
  for (const auto& c : corners) {
    double a = std::atan2(c.y - o.y, c.x - o.x);
    angles.push_back(a < 0 ? a + 2 * std::numbers::pi : a);
  }
  std::sort(angles.begin(), angles.end());

  std::vector<glm::dvec2> inner, outer;
  for (double a : angles) {
    const glm::dvec2 u(std::cos(a), std::sin(a));
    const double border = to_border(o, u, lo, hi);
    // March outwards for the last visible step, then bisect the crossing after it.
    constexpr int kSteps = 64;
    double last = 0;
    for (int i = 1; i <= kSteps; ++i) {
      const double s = border * i / kSteps * (i == kSteps ? 1 - 1e-12 : 1);
      if (seen(o + s * u)) last = s;
    }
    double in = last, out = std::min(border, last + border / kSteps);
    if (last >= border * (1 - 1e-9)) {
      in = border;
    } else {
      for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (in + out);
        (seen(o + mid * u) ? in : out) = mid;
      }
    }
    inner.push_back(o + in * u);
    outer.push_back(o + border * u);
  }

  const auto n = std::uint32_t(inner.size());
  switch (type) {
    case VisibilityMeshType::LineLoop:
      for (std::uint32_t i = 0; i < n; ++i) {
        m.vertices.emplace_back(inner[i]);
        m.indices.push_back(i);
      }
      break;
    case VisibilityMeshType::VisibleTriangles:
      m.vertices.emplace_back(o);
      for (const auto& p : inner) m.vertices.emplace_back(p);
      for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t j = (i + 1) % n;
        if (cross(o, inner[i], inner[j]) > 0) m.indices.insert(m.indices.end(), {0, 1 + i, 1 + j});
      }
      break;
    case VisibilityMeshType::HiddenTriangles:
      for (std::uint32_t i = 0; i < n; ++i) {
        m.vertices.emplace_back(inner[i]);
        m.vertices.emplace_back(outer[i]);
      }
      for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t j = (i + 1) % n;
        const std::uint32_t pi = 2 * i, qi = 2 * i + 1, pj = 2 * j, qj = 2 * j + 1;
        if (cross(inner[i], outer[i], outer[j]) > 1e-15) m.indices.insert(m.indices.end(), {pi, qi, qj});
        if (cross(inner[i], outer[j], inner[j]) > 1e-15) m.indices.insert(m.indices.end(), {pi, qj, pj});
      }
      break;
  }
  return m;
}

}  // namespace fovea::core
