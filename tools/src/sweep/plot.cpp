#include "sweep/plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "plot_canvas.hpp"


namespace fovea::sweep {
namespace {

const glm::vec4 kInk{0.1f, 0.1f, 0.1f, 1};

// The canvas' 5x7 font, `scale` pixels per font pixel (lower case drawn as upper case).
int text_width(const std::string& s, int scale) { return tools::Canvas::text_width(s, scale); }

void draw_text(tools::Canvas& c, const std::string& s, double x, double y, int scale, glm::vec4 color) {
  c.text(int(std::lround(x)), int(std::lround(y)), s, scale, color);
}

void disc(tools::Canvas& c, double cx, double cy, double r, glm::vec4 color) {
  for (int y = int(cy - r - 1); y <= int(cy + r + 1); ++y)
    for (int x = int(cx - r - 1); x <= int(cx + r + 1); ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      const double cover = std::clamp(r + 0.5 - d, 0.0, 1.0);  // one-pixel anti-aliased edge
      if (cover > 0) c.blend(x, y, {color.x, color.y, color.z, color.w * float(cover)});
    }
}

void ring(tools::Canvas& c, double cx, double cy, double r, glm::vec4 color) {
  for (int y = int(cy - r - 2); y <= int(cy + r + 2); ++y)
    for (int x = int(cx - r - 2); x <= int(cx + r + 2); ++x) {
      const double cover = std::clamp(1.0 - std::abs(std::hypot(x + 0.5 - cx, y + 0.5 - cy) - r), 0.0, 1.0);
      if (cover > 0) c.blend(x, y, {color.x, color.y, color.z, color.w * float(cover)});
    }
}

std::string tick_label(double v, double step) {
  const int decimals = std::max(0, int(-std::floor(std::log10(step) + 1e-9)));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", std::min(decimals, 6), std::abs(v) < step * 1e-6 ? 0.0 : v);
  return buf;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  }
  void pad() {
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo < 1e-12) {
      const double d = std::max(std::abs(lo) * 0.1, 1e-3);
      lo -= d, hi += d;
    }
    const double p = (hi - lo) * 0.06;
    lo -= p, hi += p;
  }
};

}  // namespace

glm::vec4 palette(std::size_t i) {
  static const glm::vec4 k[] = {{0.122f, 0.467f, 0.706f, 1}, {1.000f, 0.498f, 0.055f, 1}, {0.173f, 0.627f, 0.173f, 1},
                                {0.839f, 0.153f, 0.157f, 1}, {0.580f, 0.404f, 0.741f, 1}, {0.549f, 0.337f, 0.294f, 1},
                                {0.890f, 0.467f, 0.761f, 1}, {0.498f, 0.498f, 0.498f, 1}, {0.737f, 0.741f, 0.133f, 1},
                                {0.090f, 0.745f, 0.812f, 1}};
  return k[i % 10];
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> out;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return out;
  const double raw = (hi - lo) / std::max(1, target);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  for (double t = std::ceil(lo / step - 1e-9) * step; t <= hi + step * 1e-9; t += step) out.push_back(t);
  return out;
}

core::Image draw_chart(const Chart& chart, int W, int H) {
  tools::Canvas c(W, H);
  // The legend takes the width its longest label needs, up to 40% of the picture.
  int label_w = 0;
  for (const auto& s : chart.series) label_w = std::max(label_w, text_width(s.label, 2));
  const int legend_w = std::clamp(label_w + 60, 200, W * 2 / 5);
  const int x0 = 90, x1 = W - legend_w - 20, y0 = chart.note.empty() ? 80 : 104, y1 = H - 70;
  Range rx, ry;
  for (const auto& s : chart.series)
    for (const auto& p : s.points) rx.add(p.x), ry.add(p.y);
  rx.pad(), ry.pad();
  auto px = [&](double v) { return x0 + (x1 - x0) * (v - rx.lo) / (rx.hi - rx.lo); };
  auto py = [&](double v) { return y1 - (y1 - y0) * (v - ry.lo) / (ry.hi - ry.lo); };

  // Title and note shrink to the width when they would not fit.
  const int title_scale = text_width(chart.title, 3) <= W - 20 ? 3 : 2;
  const int note_scale = text_width(chart.note, 2) <= W - 20 ? 2 : 1;
  draw_text(c, chart.title, (W - text_width(chart.title, title_scale)) / 2.0, 14, title_scale, kInk);
  if (!chart.note.empty())
    draw_text(c, chart.note, (W - text_width(chart.note, note_scale)) / 2.0, 48, note_scale, {0.3f, 0.3f, 0.3f, 1});
  const auto xt = nice_ticks(rx.lo, rx.hi, 8), yt = nice_ticks(ry.lo, ry.hi, 7);
  for (double t : xt) {
    c.line(px(t), y0, px(t), y1, {0, 0, 0, 0.08f});
    c.line(px(t), y1, px(t), y1 + 5, kInk);
    const std::string l = tick_label(t, xt.size() > 1 ? xt[1] - xt[0] : 1);
    draw_text(c, l, px(t) - text_width(l, 2) / 2.0, y1 + 10, 2, kInk);
  }
  for (double t : yt) {
    c.line(x0, py(t), x1, py(t), {0, 0, 0, 0.08f});
    c.line(x0 - 5, py(t), x0, py(t), kInk);
    const std::string l = tick_label(t, yt.size() > 1 ? yt[1] - yt[0] : 1);
    draw_text(c, l, x0 - 9 - text_width(l, 2), py(t) - 6, 2, kInk);
  }
  c.frame(x0, y0, x1 + 1, y1 + 1, kInk);
  draw_text(c, chart.x_label, (x0 + x1 - text_width(chart.x_label, 2)) / 2.0, y1 + 38, 2, kInk);
  draw_text(c, chart.y_label, 10, y0 - 24, 2, kInk);

  for (const auto& s : chart.series) {
    if (s.line)
      for (std::size_t i = 1; i < s.points.size(); ++i)
        for (int d = 0; d < 2; ++d)  // two pixels wide
          c.line(px(s.points[i - 1].x), py(s.points[i - 1].y) + d, px(s.points[i].x), py(s.points[i].y) + d, s.color);
    if (!s.markers) continue;
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      const double X = px(s.points[i].x), Y = py(s.points[i].y);
      const bool big = i < s.emphasised.size() && s.emphasised[i];
      disc(c, X, Y, big ? 6.0 : 3.5, {s.color.x, s.color.y, s.color.z, big ? 1.0f : 0.75f});
      if (big) ring(c, X, Y, 8.0, kInk);
    }
  }

  int ly = y0 + 6;
  const int lx = x1 + 24;
  for (const auto& s : chart.series) {
    if (s.label.empty()) continue;
    if (s.line) c.rect(lx, ly + 6, lx + 22, ly + 8, s.color);
    if (s.markers) disc(c, lx + 11, ly + 7, 4, s.color);
    draw_text(c, s.label, lx + 30, ly, 2, kInk);
    ly += 24;
  }
  return c.img;
}

}  // namespace fovea::sweep
