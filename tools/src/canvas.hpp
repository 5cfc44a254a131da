#pragma once
// A small rasteriser over core::Image for the plots the tools draw (white background,
// alpha-blended pixels, DDA lines).
#include <algorithm>
#include <cmath>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "fovea/core/image.hpp"

namespace fovea::tools {

struct Canvas {
  core::Image img;
  Canvas(int w, int h) : img(w, h, {1, 1, 1, 1}) {}
  void blend(int x, int y, glm::vec4 c) {
    if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
    glm::vec4& p = img.at(x, y);
    p = glm::vec4(glm::vec3(p) * (1 - c.w) + glm::vec3(c) * c.w, 1);
  }
  void rect(int x0, int y0, int x1, int y1, glm::vec4 c) {
    for (int y = std::max(0, y0); y < std::min(img.height, y1); ++y)
      for (int x = std::max(0, x0); x < std::min(img.width, x1); ++x) blend(x, y, c);
  }
  void line(double x0, double y0, double x1, double y1, glm::vec4 c) {  // DDA, one sample per pixel step
    const int n = static_cast<int>(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0)))) + 1;
    for (int i = 0; i <= n; ++i) {
      const double u = static_cast<double>(i) / n;
      blend(static_cast<int>(std::lround(x0 + u * (x1 - x0))), static_cast<int>(std::lround(y0 + u * (y1 - y0))), c);
    }
  }
  void frame(int x0, int y0, int x1, int y1, glm::vec4 c) {
    line(x0, y0, x1 - 1, y0, c);
    line(x0, y1 - 1, x1 - 1, y1 - 1, c);
    line(x0, y0, x0, y1 - 1, c);
    line(x1 - 1, y0, x1 - 1, y1 - 1, c);
  }
};

}  // namespace fovea::tools
