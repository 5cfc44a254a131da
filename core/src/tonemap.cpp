#include "fovea/core/tonemap.hpp"

#include <algorithm>
#include <cmath>

namespace fovea::core {

double aces(double x) {
  using K = AcesCoefficients;
  return (K::k0 * x * x + K::k1 * x + K::k2) / (K::k3 * x * x + K::k4 * x + K::k5);
}

double aces_inverse(double y) {
  using K = AcesCoefficients;
  const double a = y * K::k3 - K::k0, b = y * K::k4 - K::k1, c = y * K::k5 - K::k2;
  if (std::abs(a) < 1e-12) return -c / b;
  // a < 0 and c ≥ 0 for 0 ≤ y < k0/k3: one root ≤ 0 and one ≥ 0; take the larger.
  const double d = std::sqrt(std::max(0.0, b * b - 4 * a * c));
  return std::max((-b + d) / (2 * a), (-b - d) / (2 * a));
}

glm::vec3 tonemap_linear(glm::vec3 rgb, double exposure) {
  const double scale = std::exp2(exposure);
  glm::vec3 out;
  for (int c = 0; c < 3; ++c) {
    const double x = std::isfinite(rgb[c]) ? std::max(0.0, double(rgb[c])) * scale : 0.0;
    out[c] = float(std::clamp(aces(std::min(x, 1e30)), 0.0, 1.0));
  }
  return out;
}

glm::vec3 tonemap_srgb(glm::vec3 rgb, double exposure) {
  const glm::vec3 l = tonemap_linear(rgb, exposure);
  return {srgb_encode(l.x), srgb_encode(l.y), srgb_encode(l.z)};
}

namespace {
template <class F>
Image map_pixels(const Image& img, F f) {
  Image out(img.width, img.height);
  for (std::size_t i = 0; i < img.pixels.size(); ++i) out.pixels[i] = glm::vec4(f(glm::vec3(img.pixels[i])), img.pixels[i].w);
  return out;
}
}  // namespace

Image tonemap_linear(const Image& img, double exposure) {
  return map_pixels(img, [&](glm::vec3 c) { return tonemap_linear(c, exposure); });
}
Image tonemap_srgb(const Image& img, double exposure) {
  return map_pixels(img, [&](glm::vec3 c) { return tonemap_srgb(c, exposure); });
}

}  // namespace fovea::core
