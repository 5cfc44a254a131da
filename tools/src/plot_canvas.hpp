#pragma once
// A small rasteriser over core::Image for the command-line plots: blended pixels, lines,
// rectangles and text in a built-in 5x7 bitmap font (upper-case letters, digits, a few
// signs), plus the tick spacing that keeps axes readable whatever the data range.
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec4.hpp>

#include "fovea/core/image.hpp"

namespace fovea::tools {

struct Canvas {
  core::Image img;
  Canvas(int w, int h) : img(w, h, {1, 1, 1, 1}) {}
  void blend(int x, int y, glm::vec4 c);
  void rect(int x0, int y0, int x1, int y1, glm::vec4 c);
  void line(double x0, double y0, double x1, double y1, glm::vec4 c);  // DDA, one step per pixel
  void frame(int x0, int y0, int x1, int y1, glm::vec4 c);
  // Text with its top-left corner at (x, y); `scale` pixels per font pixel. Lower case is
  // drawn as upper case; characters without a glyph as a blank.
  void text(int x, int y, std::string_view s, int scale, glm::vec4 c);
  static int text_width(std::string_view s, int scale) { return static_cast<int>(s.size()) * 6 * scale; }
  static int text_height(int scale) { return 7 * scale; }
};

// Tick values in [lo, hi] at a 1, 2 or 5 × 10^k spacing, at most `max_ticks` of them (the
// count is bounded whatever the span, e.g. a recording over 9e18 ns).
std::vector<double> nice_ticks(double lo, double hi, int max_ticks);
// A tick value as text, with as many decimals as the spacing needs.
std::string tick_label(double v, double step);

}  // namespace fovea::tools
