#pragma once
// Line and scatter charts as PNG-ready images: axes with numbered ticks, axis labels,
// title and legend. Text is the plot canvas' built-in 5x7 font (plot_canvas.hpp), so no font file is needed.
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "fovea/core/image.hpp"

namespace fovea::sweep {

struct Series {
  std::string label;  // empty: not in the legend
  glm::vec4 color{0, 0, 0, 1};
  std::vector<glm::dvec2> points;
  bool line = false;              // connect the points in their order
  bool markers = true;
  std::vector<bool> emphasised;   // per point: drawn larger and ringed (e.g. a Pareto front)
};

struct Chart {
  std::string title, x_label, y_label, note;  // note: a line under the title
  std::vector<Series> series;
};

core::Image draw_chart(const Chart& chart, int width = 1000, int height = 640);

// Distinct colours for series i (Tableau 10).
glm::vec4 palette(std::size_t i);
// Tick positions at 1, 2 or 5 × 10^k covering [lo, hi] with about `target` ticks.
std::vector<double> nice_ticks(double lo, double hi, int target);

}  // namespace fovea::sweep
