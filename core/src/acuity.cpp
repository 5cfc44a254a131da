#include "fovea/core/acuity.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace fovea::core::acuity {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kScale = 14.98 * kPi / 0.09;  // P4 Eq. 5: 166.4π
// Continuity constant at the fovea edge (P4 prints the rounded −612.3).
const double kC = (1.0 / (0.3 * kFoveaDeg + 1) + std::log(0.3 * kFoveaDeg + 1)) * kScale -
                  kPi * kFoveaDeg * kFoveaDeg;
const double kH80 = h(kTruncDeg);
}  // namespace

double m(double e) {
  if (!(e > kFoveaDeg)) return 1.0;  // also e <= 0 and NaN (treated as the gaze itself)
  const double t = 0.3 * e + 1.0;
  return 7.49 / (t * t);
}

double h(double x) {
  if (!(x > 0)) return 0.0;
  if (x <= kFoveaDeg) return kPi * x * x;
  const double t = 0.3 * x + 1.0;
  return (1.0 / t + std::log(t)) * kScale - kC;
}

double lambert_w0(double x) {
  if (!(x >= -1.0 / std::numbers::e)) return std::nan("");
  if (x == 0) return 0;
  // Start: branch-point series near -1/e, log asymptote for large x, else w ~ x.
  double w;
  if (x < -0.25) {
    const double p = std::sqrt(2.0 * (std::numbers::e * x + 1.0));
    w = -1.0 + p - p * p / 3.0;
  } else if (x > 3) {
    const double l = std::log(x);
    w = l - std::log(l);
  } else {
    w = x / (1 + x);
  }
  for (int i = 0; i < 32; ++i) {  // Halley iteration
    const double ew = std::exp(w);
    const double f = w * ew - x;
    const double d = ew * (w + 1) - (w + 2) * f / (2 * w + 2);
    if (d == 0 || !std::isfinite(d)) break;
    const double step = f / d;
    w -= step;
    if (std::abs(step) <= 1e-15 * (1 + std::abs(w))) break;
  }
  return w;
}

double h_inverse(double y) {
  if (!(y > 0)) return 0.0;
  if (y <= kPi * kFoveaDeg * kFoveaDeg) return std::sqrt(y / kPi);
  // 1/t + ln t = c with c = (y + C)/scale, t = 0.3x + 1 > 1. With u = 1/t:
  // u − ln u = c  =>  −u·e^(−u) = −e^(−c)  =>  u = −W0(−e^(−c)).
  const double c = (y + kC) / kScale;
  const double u = -lambert_w0(-std::exp(-c));
  return (1.0 / u - 1.0) / 0.3;
}

double cdf(double x) { return h(std::min(x, kTruncDeg)) / kH80; }

double cdf_inverse(double u) { return h_inverse(std::clamp(u, 0.0, 1.0) * kH80); }

double cdf_inverse_p4(double u) {
  u = std::clamp(u, 0.0, 1.0);
  if (u <= kP4Branch) return 18.64 * std::sqrt(u);
  return (((25.09 * u + 0.1680) * u + 27.61) * u + 23.87) * u + 3.232;
}

double cdf_p4(double x) {
  if (!(x > 0)) return 0.0;
  const double edge = cdf_inverse_p4(kP4Branch);
  if (x <= 18.64 * std::sqrt(kP4Branch)) return std::min(kP4Branch, (x / 18.64) * (x / 18.64));
  if (x <= edge) return kP4Branch;  // the two branches meet 0.005° apart (P4's fit)
  if (x >= cdf_inverse_p4(1.0)) return 1.0;
  // The quartic is increasing on [0.0965, 1]: bisection, then Newton polish.
  double lo = kP4Branch, hi = 1.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (cdf_inverse_p4(mid) < x ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace fovea::core::acuity
