#include "fovea/core/view.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"

namespace fovea::core {

namespace {
constexpr double kRadPerDeg = std::numbers::pi / 180.0;
}

Fov Fov::from_degrees(double left, double right, double up, double down) {
  return {left * kRadPerDeg, right * kRadPerDeg, up * kRadPerDeg, down * kRadPerDeg};
}

Fov Fov::mirrored() const { return {-angle_right, -angle_left, angle_up, angle_down}; }

View::View(const Fov& fov, int width, int height, const Pose& pose)
    : fov_(fov), pose_(pose), width_(width), height_(height) {
  const double lim = std::numbers::pi / 2 - 1e-6;
  const double a[4] = {fov.angle_left, fov.angle_right, fov.angle_up, fov.angle_down};
  for (double v : a)
    if (!std::isfinite(v) || std::abs(v) >= lim)
      throw InputError("field of view: half-angles must be finite and below 90 degrees");
  if (!(fov.angle_left < fov.angle_right) || !(fov.angle_down < fov.angle_up))
    throw InputError("field of view: need left < right and down < up");
  if (width < 1 || height < 1)
    throw InputError("display: raster must be at least 1x1, got " + std::to_string(width) + "x" +
                     std::to_string(height));
  tl_ = std::tan(fov.angle_left);
  tr_ = std::tan(fov.angle_right);
  tu_ = std::tan(fov.angle_up);
  td_ = std::tan(fov.angle_down);
}

glm::dvec3 View::pixel_to_dir(glm::dvec2 px) const {
  const double tx = tl_ + (px.x / width_) * (tr_ - tl_);
  const double ty = tu_ - (px.y / height_) * (tu_ - td_);
  return glm::normalize(glm::dvec3(tx, ty, -1.0));
}

std::optional<glm::dvec2> View::dir_to_pixel(glm::dvec3 d) const {
  if (!(d.z < 0) || !std::isfinite(d.x) || !std::isfinite(d.y)) return std::nullopt;
  const double tx = d.x / -d.z, ty = d.y / -d.z;
  if (!std::isfinite(tx) || !std::isfinite(ty)) return std::nullopt;
  return glm::dvec2((tx - tl_) / (tr_ - tl_) * width_, (tu_ - ty) / (tu_ - td_) * height_);
}

glm::dvec3 View::centre_dir() const { return pixel_to_dir({width_ * 0.5, height_ * 0.5}); }

double View::pixels_per_deg2(glm::dvec3 d) const {
  // dΩ = dtx·dty / (1 + tx² + ty²)^(3/2) on the z = -1 plane.
  const double tx = d.x / -d.z, ty = d.y / -d.z;
  const double px_per_t2 = (width_ / (tr_ - tl_)) * (height_ / (tu_ - td_));
  const double q = 1.0 + tx * tx + ty * ty;
  return px_per_t2 * q * std::sqrt(q) * kRadPerDeg * kRadPerDeg;
}

void View::corner_dirs(glm::dvec3 out[4]) const {
  out[0] = glm::normalize(glm::dvec3(tl_, tu_, -1));
  out[1] = glm::normalize(glm::dvec3(tr_, tu_, -1));
  out[2] = glm::normalize(glm::dvec3(tr_, td_, -1));
  out[3] = glm::normalize(glm::dvec3(tl_, td_, -1));
}

bool View::clamp_to_frustum(glm::dvec3& d) const {
  const double len = glm::length(d);
  if (!std::isfinite(len) || len < 1e-12) return false;
  if (!(d.z < 0)) return false;
  double tx = d.x / -d.z, ty = d.y / -d.z;
  if (!std::isfinite(tx) || !std::isfinite(ty)) return false;
  tx = std::clamp(tx, tl_, tr_);
  ty = std::clamp(ty, td_, tu_);
  d = glm::normalize(glm::dvec3(tx, ty, -1));
  return true;
}

double angle_deg(glm::dvec3 a, glm::dvec3 b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) / kRadPerDeg;
}

}  // namespace fovea::core
