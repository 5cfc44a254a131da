#include "fovea/core/metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "fovea/core/acuity.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/flip.hpp"
#include "fovea/core/tonemap.hpp"

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

// Luma (Rec. 709 weights) of the sRGB-encoded display transform: SSIM's and flicker's input.
std::vector<double> tone_mapped_luma(const Image& img, double exposure = 0.0) {
  std::vector<double> out(img.pixels.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const glm::vec3 c = tonemap_srgb(glm::vec3(img.pixels[i]), exposure);
    out[i] = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
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

double ssim(const Image& a, const Image& b) { return weighted_mean(ssim_map(a, b)); }

std::vector<float> ssim_map(const Image& a, const Image& b) {
  require_same_size(a, b, "ssim");
  constexpr int kR = kSsimRadius;
  constexpr double kSigma = 1.5, kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
  double w1[2 * kR + 1];
  for (int k = -kR; k <= kR; ++k) w1[k + kR] = std::exp(-0.5 * k * k / (kSigma * kSigma));
  const std::vector<double> x = tone_mapped_luma(a), y = tone_mapped_luma(b);
  const int W = a.width, H = a.height;
  // Separable moments x, y, x², y², xy; windows cut by the border are renormalised.
  std::array<std::vector<double>, 5> m;
  for (auto& p : m) p.assign(x.size(), 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) m[0][i] = x[i], m[1][i] = y[i], m[2][i] = x[i] * x[i], m[3][i] = y[i] * y[i], m[4][i] = x[i] * y[i];
  std::vector<double> tmp(x.size());
  for (auto& p : m)
    for (int pass = 0; pass < 2; ++pass) {
      const int n = pass == 0 ? W : H;
      for (int r = 0; r < H; ++r)
        for (int c = 0; c < W; ++c) {
          const int at = pass == 0 ? c : r;
          double s = 0, ws = 0;
          for (int k = std::max(-kR, -at); k <= std::min(kR, n - 1 - at); ++k) {
            const std::size_t j = pass == 0 ? std::size_t(r) * W + c + k : std::size_t(r + k) * W + c;
            s += w1[k + kR] * p[j];
            ws += w1[k + kR];
          }
          tmp[std::size_t(r) * W + c] = s / ws;
        }
      p.swap(tmp);
    }
  std::vector<float> out(x.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double mx = m[0][i], my = m[1][i];
    const double vx = m[2][i] - mx * mx, vy = m[3][i] - my * my, cov = m[4][i] - mx * my;
    out[i] = float(((2 * mx * my + kC1) * (2 * cov + kC2)) / ((mx * mx + my * my + kC1) * (vx + vy + kC2)));
  }
  return out;
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

ErrorMaps error_maps(const Image& test, const Image& reference, double ppd, double exposure,
                     const std::vector<bool>& valid) {
  require_same_size(test, reference, "error_maps");
  ErrorMaps m;
  const std::size_t n = test.pixels.size();
  m.squared_error.resize(n);
  m.rel_mse.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 t = tonemap_srgb(glm::vec3(test.pixels[i]), exposure),
                    r = tonemap_srgb(glm::vec3(reference.pixels[i]), exposure);
    const glm::vec3 d = t - r;
    m.squared_error[i] = glm::dot(d, d) / 3.0f;
    double rel = 0;
    for (int c = 0; c < 3; ++c) {
      const double tc = finite(test.pixels[i][c]), rc = finite(reference.pixels[i][c]);
      rel += (tc - rc) * (tc - rc) / (rc * rc + kRelMseEpsilon);
    }
    m.rel_mse[i] = float(std::min(rel / 3.0, 1e30));
  }
  m.ssim = ssim_map(test, reference);
  m.ldr_flip = ldr_flip(tonemap_linear(test, exposure), tonemap_linear(reference, exposure), ppd);
  m.hdr_flip = hdr_flip(test, reference, ppd, valid).error;
  return m;
}

int error_map_support_px(double ppd) { return std::max(kSsimRadius, flip_support_px(ppd)); }

std::vector<bool> scorable_pixels(const std::vector<bool>& valid, int width, int height, int radius) {
  if (width < 1 || height < 1 || valid.size() != std::size_t(width) * std::size_t(height))
    throw InputError("scorable_pixels: mask size differs from " + std::to_string(width) + "x" + std::to_string(height));
  if (radius < 0) throw InputError("scorable_pixels: radius must be >= 0");
  // Erosion by a (2r+1)² square, separably: a pixel stays when its row segment, then its
  // column segment of row results, holds no invalid pixel. Running counts of invalid pixels
  // keep it linear in the image size.
  const auto erode = [&](const std::vector<bool>& in, bool along_x) {
    std::vector<bool> out(in.size());
    const int lines = along_x ? height : width, n = along_x ? width : height;
    for (int l = 0; l < lines; ++l) {
      const auto at = [&](int k) { return along_x ? std::size_t(l) * width + k : std::size_t(k) * width + l; };
      int bad = 0;  // invalid pixels in [k − r, k + r] ∩ [0, n)
      for (int k = 0; k < std::min(radius, n); ++k) bad += in[at(k)] ? 0 : 1;
      for (int k = 0; k < n; ++k) {
        if (k + radius < n) bad += in[at(k + radius)] ? 0 : 1;
        if (k - radius - 1 >= 0) bad -= in[at(k - radius - 1)] ? 0 : 1;
        out[at(k)] = bad == 0;
      }
    }
    return out;
  };
  return erode(erode(valid, true), false);
}

double weighted_mean(const std::vector<float>& map, const std::vector<float>& weights) {
  if (!weights.empty() && weights.size() != map.size())
    throw InputError("weighted_mean: weight map size differs from the error map size");
  double s = 0, ws = 0;
  for (std::size_t i = 0; i < map.size(); ++i) {
    const double w = weights.empty() ? 1.0 : std::max(0.0, finite(weights[i]));
    s += w * finite(map[i]);
    ws += w;
  }
  return ws > 0 ? s / ws : 0.0;
}

Scores pool(const ErrorMaps& maps, const std::vector<float>& weights) {
  Scores s;
  for (const auto w : weights) s.weight += std::max(0.0, finite(w));
  if (weights.empty()) s.weight = double(maps.squared_error.size());
  if (!(s.weight > 0)) return s;
  s.psnr = psnr_from_mse(weighted_mean(maps.squared_error, weights));
  s.ssim = weighted_mean(maps.ssim, weights);
  s.rel_mse = weighted_mean(maps.rel_mse, weights);
  s.ldr_flip = weighted_mean(maps.ldr_flip, weights);
  s.hdr_flip = weighted_mean(maps.hdr_flip, weights);
  return s;
}

int band_index(float e, double band_deg) {
  int k = std::max(0, int(e / band_deg));  // the quotient's rounding can land one off
  while (k > 0 && e < k * band_deg) --k;
  while (e >= (k + 1) * band_deg) ++k;
  return k;
}

std::vector<BandScores> band_scores(const ErrorMaps& maps, const std::vector<float>& ecc, double band_deg) {
  if (ecc.size() != maps.squared_error.size())
    throw InputError("band_scores: eccentricity map size differs from the image size");
  if (!(band_deg > 0)) throw InputError("band_scores: band width must be > 0");
  float e_max = 0;
  for (float e : ecc)
    if (std::isfinite(e)) e_max = std::max(e_max, e);
  std::vector<BandScores> out;
  std::vector<float> w(ecc.size());
  for (int k = 0; k <= int(e_max / band_deg); ++k) {
    const double lo = k * band_deg, hi = (k + 1) * band_deg;
    long n = 0;
    for (std::size_t i = 0; i < ecc.size(); ++i) n += (w[i] = std::isfinite(ecc[i]) && ecc[i] >= lo && ecc[i] < hi) ? 1 : 0;
    if (n) out.push_back({lo, hi, n, pool(maps, w)});
  }
  return out;
}

std::vector<float> foveation_weights(const std::vector<float>& ecc) {
  std::vector<float> w(ecc.size());
  for (std::size_t i = 0; i < ecc.size(); ++i) w[i] = std::isfinite(ecc[i]) ? float(acuity::m(std::max(0.0f, ecc[i]))) : 0.0f;
  return w;
}

std::vector<float> flicker_map(const std::vector<Image>& frames, double exposure) {
  if (frames.size() < 2) throw InputError("flicker_map: needs at least 2 frames");
  for (const Image& f : frames) require_same_size(frames[0], f, "flicker_map");
  std::vector<double> s(frames[0].pixels.size(), 0.0), s2 = s;
  for (const Image& f : frames) {
    const std::vector<double> y = tone_mapped_luma(f, exposure);
    for (std::size_t i = 0; i < y.size(); ++i) s[i] += y[i], s2[i] += y[i] * y[i];
  }
  const double n = double(frames.size());
  std::vector<float> out(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) out[i] = float(std::sqrt(std::max(0.0, s2[i] / n - (s[i] / n) * (s[i] / n))));
  return out;
}

}  // namespace fovea::core
