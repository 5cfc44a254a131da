#include "fovea/core/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "fovea/core/acuity.hpp"
#include "fovea/core/error.hpp"

namespace fovea::core {

namespace {

void require_same_size(const Image& a, const Image& b, const char* what) {
  if (a.width != b.width || a.height != b.height || a.pixels.size() != b.pixels.size() || a.pixels.empty())
    throw InputError(std::string(what) + ": images must be non-empty and of equal size (" + std::to_string(a.width) +
                     "x" + std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                     std::to_string(b.height) + ")");
}

// Non-finite values count as 0 so a metric never turns NaN.
double finite(double v) { return std::isfinite(v) ? v : 0.0; }

double psnr_from_mse(double mse) {
  if (!(mse > 1e-10)) return kPsnrIdentical;
  return std::min(kPsnrIdentical, 10.0 * std::log10(1.0 / mse));
}

double squared_error(const glm::vec4& p, const glm::vec4& q) {
  double s = 0;
  for (int c = 0; c < 3; ++c) {
    const double d = finite(p[c]) - finite(q[c]);
    s += d * d;
  }
  return s / 3.0;
}

double luminance(const glm::vec4& p) { return 0.2126 * finite(p.x) + 0.7152 * finite(p.y) + 0.0722 * finite(p.z); }

// SSIM's input: Reinhard on luminance (c / (1 + L)), sRGB-encoded luminance of the result.
std::vector<double> tone_mapped_luma(const Image& img) {
  std::vector<double> out(img.pixels.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double l = std::max(0.0, luminance(img.pixels[i]));
    out[i] = srgb_encode(float(l / (1.0 + l)));
  }
  return out;
}

// One separable pass of a Gaussian with per-output-pixel σ along x (dx = 1) or y.
void gaussian_pass(const Image& in, Image& out, const std::vector<float>& sigma, bool along_x) {
  constexpr int kMaxRadius = 64;
  const int n = along_x ? in.width : in.height;
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      const std::size_t i = std::size_t(y) * in.width + x;
      const double s = std::isfinite(sigma[i]) ? std::max(0.0, double(sigma[i])) : 0.0;
      if (s < 0.05) {
        out.pixels[i] = in.pixels[i];
        continue;
      }
      const int radius = std::min(kMaxRadius, int(std::ceil(3.0 * s)));
      const int c = along_x ? x : y;
      glm::dvec3 acc(0);
      double wsum = 0;
      for (int k = std::max(-radius, -c); k <= std::min(radius, n - 1 - c); ++k) {
        const double w = std::exp(-0.5 * k * k / (s * s));
        const glm::vec4& p = along_x ? in.at(x + k, y) : in.at(x, y + k);
        acc += w * glm::dvec3(finite(p.x), finite(p.y), finite(p.z));
        wsum += w;
      }
      const glm::dvec3 r = acc / wsum;
      out.pixels[i] = glm::vec4(float(r.x), float(r.y), float(r.z), in.pixels[i].w);
    }
}

}  // namespace

double psnr(const Image& a, const Image& b) {
  require_same_size(a, b, "psnr");
  double s = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) s += squared_error(a.pixels[i], b.pixels[i]);
  return psnr_from_mse(s / double(a.pixels.size()));
}

double psnr_masked(const Image& a, const Image& b, const std::vector<bool>& mask) {
  require_same_size(a, b, "psnr");
  if (mask.size() != a.pixels.size()) throw InputError("psnr: mask size differs from the image size");
  double s = 0;
  long n = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    if (mask[i]) {
      s += squared_error(a.pixels[i], b.pixels[i]);
      ++n;
    }
  return n ? psnr_from_mse(s / double(n)) : kPsnrIdentical;
}

double ssim(const Image& a, const Image& b) {
  require_same_size(a, b, "ssim");
  constexpr int kR = 5;  // 11×11 window
  constexpr double kSigma = 1.5, kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
  double w1[2 * kR + 1], wsum = 0;
  for (int k = -kR; k <= kR; ++k) wsum += w1[k + kR] = std::exp(-0.5 * k * k / (kSigma * kSigma));
  for (double& w : w1) w /= wsum;
  const std::vector<double> x = tone_mapped_luma(a), y = tone_mapped_luma(b);
  const int W = a.width, H = a.height;
  // Separable moments: horizontal pass into five planes, then vertical per valid window.
  std::vector<double> hx(x.size()), hy(x.size()), hxx(x.size()), hyy(x.size()), hxy(x.size());
  for (int r = 0; r < H; ++r)
    for (int c = kR; c < W - kR; ++c) {
      double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
      for (int k = -kR; k <= kR; ++k) {
        const std::size_t j = std::size_t(r) * W + c + k;
        const double w = w1[k + kR];
        sx += w * x[j], sy += w * y[j], sxx += w * x[j] * x[j], syy += w * y[j] * y[j], sxy += w * x[j] * y[j];
      }
      const std::size_t i = std::size_t(r) * W + c;
      hx[i] = sx, hy[i] = sy, hxx[i] = sxx, hyy[i] = syy, hxy[i] = sxy;
    }
  double total = 0;
  long count = 0;
  for (int r = kR; r < H - kR; ++r)
    for (int c = kR; c < W - kR; ++c) {
      double mx = 0, my = 0, mxx = 0, myy = 0, mxy = 0;
      for (int k = -kR; k <= kR; ++k) {
        const std::size_t j = std::size_t(r + k) * W + c;
        const double w = w1[k + kR];
        mx += w * hx[j], my += w * hy[j], mxx += w * hxx[j], myy += w * hyy[j], mxy += w * hxy[j];
      }
      const double vx = mxx - mx * mx, vy = myy - my * my, cov = mxy - mx * my;
      total += ((2 * mx * my + kC1) * (2 * cov + kC2)) / ((mx * mx + my * my + kC1) * (vx + vy + kC2));
      ++count;
    }
  if (count == 0) {  // smaller than one window: the global statistics
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
    mx /= double(x.size()), my /= double(x.size());
    double vx = 0, vy = 0, cov = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      vx += (x[i] - mx) * (x[i] - mx), vy += (y[i] - my) * (y[i] - my), cov += (x[i] - mx) * (y[i] - my);
    vx /= double(x.size()), vy /= double(x.size()), cov /= double(x.size());
    return ((2 * mx * my + kC1) * (2 * cov + kC2)) / ((mx * mx + my * my + kC1) * (vx + vy + kC2));
  }
  return total / double(count);
}

double temporal_error(const Image& previous, const Image& current) {
  require_same_size(previous, current, "temporal_error");
  double s = 0;
  for (std::size_t i = 0; i < current.pixels.size(); ++i)
    s += std::abs(luminance(current.pixels[i]) - luminance(previous.pixels[i]));
  return s / double(current.pixels.size());
}

std::vector<float> eccentricity_map(const View& view, glm::dvec3 gaze) {
  std::vector<float> e(std::size_t(view.width()) * view.height());
  for (int y = 0; y < view.height(); ++y)
    for (int x = 0; x < view.width(); ++x)
      e[std::size_t(y) * view.width() + x] = float(angle_deg(view.pixel_to_dir({x + 0.5, y + 0.5}), gaze));
  return e;
}

std::vector<BandPsnr> band_psnr(const Image& a, const Image& b, const std::vector<float>& ecc, double band_deg) {
  require_same_size(a, b, "band_psnr");
  if (ecc.size() != a.pixels.size()) throw InputError("band_psnr: eccentricity map size differs from the image size");
  if (!(band_deg > 0)) throw InputError("band_psnr: band width must be > 0");
  float e_max = 0;
  for (float e : ecc)
    if (std::isfinite(e)) e_max = std::max(e_max, e);
  const int bands = int(e_max / band_deg) + 1;
  std::vector<double> se(bands, 0.0);
  std::vector<long> n(bands, 0);
  for (std::size_t i = 0; i < ecc.size(); ++i) {
    if (!std::isfinite(ecc[i])) continue;
    const int k = std::clamp(int(ecc[i] / band_deg), 0, bands - 1);
    se[k] += squared_error(a.pixels[i], b.pixels[i]);
    ++n[k];
  }
  std::vector<BandPsnr> out;
  for (int k = 0; k < bands; ++k)
    if (n[k]) out.push_back({k * band_deg, (k + 1) * band_deg, n[k], psnr_from_mse(se[k] / double(n[k]))});
  return out;
}

double fovea_psnr(const Image& a, const Image& b, const std::vector<float>& ecc) {
  if (ecc.size() != a.pixels.size()) throw InputError("fovea_psnr: eccentricity map size differs from the image size");
  std::vector<bool> mask(ecc.size());
  for (std::size_t i = 0; i < ecc.size(); ++i) mask[i] = ecc[i] <= acuity::kFoveaDeg;
  return psnr_masked(a, b, mask);
}

double acuity_sigma_deg(double ecc_deg) {
  const double v = 60.0 * acuity::m(std::max(0.0, ecc_deg));  // cycles per degree
  return std::sqrt(std::log(2.0) / 2.0) / (std::numbers::pi * v);
}

Image variable_gaussian(const Image& img, const std::vector<float>& sigma_px) {
  if (sigma_px.size() != img.pixels.size()) throw InputError("variable_gaussian: sigma map size differs from the image");
  Image tmp(img.width, img.height), out(img.width, img.height);
  gaussian_pass(img, tmp, sigma_px, true);
  gaussian_pass(tmp, out, sigma_px, false);
  return out;
}

double foveated_psnr(const Image& a, const Image& b, const View& view, glm::dvec3 gaze) {
  require_same_size(a, b, "foveated_psnr");
  if (a.width != view.width() || a.height != view.height())
    throw InputError("foveated_psnr: image size differs from the view's raster");
  std::vector<float> sigma(a.pixels.size());
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const glm::dvec3 d = view.pixel_to_dir({x + 0.5, y + 0.5});
      const double px_per_deg = std::sqrt(view.pixels_per_deg2(d));
      sigma[std::size_t(y) * a.width + x] = float(acuity_sigma_deg(angle_deg(d, gaze)) * px_per_deg);
    }
  return psnr(variable_gaussian(a, sigma), variable_gaussian(b, sigma));
}

}  // namespace fovea::core
