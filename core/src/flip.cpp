#include "fovea/core/flip.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "fovea/core/error.hpp"
#include "fovea/core/tonemap.hpp"

namespace fovea::core {

namespace {

// Constants of LDR-FLIP (Andersson et al. 2020): colour compression and redistribution
// (Sec. 4.1), feature width w in degrees and its exponent (Sec. 4.2).
constexpr double kQc = 0.7, kPc = 0.4, kPt = 0.95, kQf = 0.5, kFeatureWidthDeg = 0.082;
// Contrast sensitivity as sums of Gaussians per opponent channel (Sec. 4.1, from Johnson &
// Fairchild 2003): spatial S(x) = Σ a·√(π/b)·exp(−π²x²/b), x in degrees.
struct CsfTerm {
  double a, b;
};
constexpr std::array<std::array<CsfTerm, 2>, 3> kCsf{{
    {{{1.0, 0.0047}, {0.0, 1e-5}}},    // achromatic Yy
    {{{1.0, 0.0053}, {0.0, 1e-5}}},    // red-green Cx
    {{{34.1, 0.04}, {13.5, 0.025}}},   // blue-yellow Cz
}};
constexpr double kCsfMaxB = 0.04;

// Linear sRGB (D65) <-> CIE XYZ, IEC 61966-2-1.
glm::dvec3 rgb_to_xyz(glm::dvec3 c) {
  return {0.4124564 * c.x + 0.3575761 * c.y + 0.1804375 * c.z, 0.2126729 * c.x + 0.7151522 * c.y + 0.0721750 * c.z,
          0.0193339 * c.x + 0.1191920 * c.y + 0.9503041 * c.z};
}
glm::dvec3 xyz_to_rgb(glm::dvec3 x) {
  return {3.2404542 * x.x - 1.5371385 * x.y - 0.4985314 * x.z, -0.9692660 * x.x + 1.8760108 * x.y + 0.0415560 * x.z,
          0.0556434 * x.x - 0.2040259 * x.y + 1.0572252 * x.z};
}
const glm::dvec3 kWhite = rgb_to_xyz({1, 1, 1});  // reference white of YyCxCz and L*a*b*

// YyCxCz, the linearised CIELab of the CSF stage (2020, Sec. 4.1).
glm::dvec3 xyz_to_ycxcz(glm::dvec3 x) {
  const glm::dvec3 r = x / kWhite;
  return {116.0 * r.y - 16.0, 500.0 * (r.x - r.y), 200.0 * (r.y - r.z)};
}
glm::dvec3 ycxcz_to_xyz(glm::dvec3 v) {
  const double y = (v.x + 16.0) / 116.0;
  return glm::dvec3(v.y / 500.0 + y, y, y - v.z / 200.0) * kWhite;
}

double lab_f(double t) {
  constexpr double d = 6.0 / 29.0;
  return t > d * d * d ? std::cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
}
glm::dvec3 xyz_to_lab(glm::dvec3 x) {
  const glm::dvec3 r = x / kWhite;
  const double fx = lab_f(r.x), fy = lab_f(r.y), fz = lab_f(r.z);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}
// FLIP's inputs live in [0, 1]; non-finite channels count as 0.
glm::dvec3 unit_rgb(const glm::vec4& p) {
  glm::dvec3 c;
  for (int i = 0; i < 3; ++i) c[i] = std::isfinite(p[i]) ? std::clamp(double(p[i]), 0.0, 1.0) : 0.0;
  return c;
}

glm::dvec3 hunt(glm::dvec3 lab) { return {lab.x, 0.01 * lab.x * lab.y, 0.01 * lab.x * lab.z}; }

// Filter radii in pixels: the CSF's widest Gaussian to 3σ, the feature detector's σ = w/2 to 3σ.
int csf_radius(double ppd) {
  const double pi = std::numbers::pi;
  return int(std::ceil(3.0 * std::sqrt(kCsfMaxB / (2.0 * pi * pi)) * ppd));
}
double feature_sigma(double ppd) { return 0.5 * kFeatureWidthDeg * ppd; }
int feature_radius(double ppd) { return int(std::ceil(3.0 * feature_sigma(ppd))); }

// A W×H plane, convolved separably with clamp-to-edge borders.
struct Plane {
  int w = 0, h = 0;
  std::vector<double> v;
  double at(int x, int y) const { return v[std::size_t(std::clamp(y, 0, h - 1)) * w + std::clamp(x, 0, w - 1)]; }
};
Plane convolve(const Plane& in, const std::vector<double>& kx, const std::vector<double>& ky) {
  const int rx = int(kx.size() / 2), ry = int(ky.size() / 2);
  Plane tmp{in.w, in.h, std::vector<double>(in.v.size())}, out = tmp;
  for (int y = 0; y < in.h; ++y)
    for (int x = 0; x < in.w; ++x) {
      double s = 0;
      for (int k = -rx; k <= rx; ++k) s += kx[std::size_t(k + rx)] * in.at(x + k, y);
      tmp.v[std::size_t(y) * in.w + x] = s;
    }
  for (int y = 0; y < in.h; ++y)
    for (int x = 0; x < in.w; ++x) {
      double s = 0;
      for (int k = -ry; k <= ry; ++k) s += ky[std::size_t(k + ry)] * tmp.at(x, y + k);
      out.v[std::size_t(y) * in.w + x] = s;
    }
  return out;
}

// Scales the positive taps to sum 1 and the negative ones to sum −1 (2020, Sec. 4.2).
std::vector<double> balance(std::vector<double> k) {
  double pos = 0, neg = 0;
  for (double v : k) (v > 0 ? pos : neg) += v;
  for (double& v : k) v = v > 0 ? v / pos : (v < 0 ? -v / neg : 0.0);
  return k;
}

// YyCxCz planes of an image after the CSF filters, back in linear RGB clamped to [0, 1],
// then Hunt-adjusted Lab per pixel.
std::vector<glm::dvec3> filtered_hunt_lab(const Image& img, double ppd) {
  const int w = img.width, h = img.height;
  std::array<Plane, 3> opp;
  for (auto& p : opp) p = {w, h, std::vector<double>(img.pixels.size())};
  for (std::size_t i = 0; i < img.pixels.size(); ++i) {
    const glm::dvec3 o = xyz_to_ycxcz(rgb_to_xyz(unit_rgb(img.pixels[i])));
    for (int ch = 0; ch < 3; ++ch) opp[ch].v[i] = o[ch];
  }
  const double pi = std::numbers::pi;
  const int r = csf_radius(ppd);
  for (int ch = 0; ch < 3; ++ch) {
    // Σ_i c_i·G_i(x)G_i(y) normalised to unit sum; each Gaussian term separably.
    Plane acc{w, h, std::vector<double>(img.pixels.size(), 0.0)};
    double total = 0;
    std::vector<std::pair<double, Plane>> terms;
    for (const CsfTerm& t : kCsf[std::size_t(ch)]) {
      if (t.a <= 0) continue;
      std::vector<double> g(std::size_t(2 * r + 1));
      double sum = 0;
      for (int k = -r; k <= r; ++k) sum += g[std::size_t(k + r)] = std::exp(-pi * pi * (k / ppd) * (k / ppd) / t.b);
      const double c = t.a * std::sqrt(pi / t.b);
      total += c * sum * sum;
      terms.emplace_back(c, convolve(opp[std::size_t(ch)], g, g));
    }
    for (const auto& [c, p] : terms)
      for (std::size_t i = 0; i < acc.v.size(); ++i) acc.v[i] += c * p.v[i] / total;
    opp[std::size_t(ch)] = std::move(acc);
  }
  std::vector<glm::dvec3> out(img.pixels.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const glm::dvec3 rgb = glm::clamp(xyz_to_rgb(ycxcz_to_xyz({opp[0].v[i], opp[1].v[i], opp[2].v[i]})), 0.0, 1.0);
    out[i] = hunt(xyz_to_lab(rgb_to_xyz(rgb)));
  }
  return out;
}

// Edge and point magnitudes of the normalised achromatic channel Y/Yn (2020, Sec. 4.2):
// first and second derivatives of a Gaussian with σ = w/2 degrees.
struct Features {
  std::vector<double> edge, point;
};
Features features(const Image& img, double ppd) {
  const double sigma = feature_sigma(ppd);
  const int r = feature_radius(ppd);
  std::vector<double> g(std::size_t(2 * r + 1)), d = g, p = g;
  double gs = 0;
  for (int k = -r; k <= r; ++k) {
    const double e = std::exp(-0.5 * k * k / (sigma * sigma));
    g[std::size_t(k + r)] = e;
    d[std::size_t(k + r)] = -k * e;
    p[std::size_t(k + r)] = (k * k / (sigma * sigma) - 1.0) * e;
    gs += e;
  }
  for (double& v : g) v /= gs;
  d = balance(d);
  p = balance(p);
  Plane y{img.width, img.height, std::vector<double>(img.pixels.size())};
  for (std::size_t i = 0; i < y.v.size(); ++i) {
    y.v[i] = rgb_to_xyz(unit_rgb(img.pixels[i])).y / kWhite.y;
  }
  const Plane ex = convolve(y, d, g), ey = convolve(y, g, d), px = convolve(y, p, g), py = convolve(y, g, p);
  Features f{std::vector<double>(y.v.size()), std::vector<double>(y.v.size())};
  for (std::size_t i = 0; i < y.v.size(); ++i) {
    f.edge[i] = std::hypot(ex.v[i], ey.v[i]);
    f.point[i] = std::hypot(px.v[i], py.v[i]);
  }
  return f;
}

void require_inputs(const Image& a, const Image& b, double ppd, const char* what) {
  if (a.width != b.width || a.height != b.height || a.pixels.size() != b.pixels.size() || a.pixels.empty())
    throw InputError(std::string(what) + ": images must be non-empty and of equal size (" + std::to_string(a.width) +
                     "x" + std::to_string(a.height) + " vs " + std::to_string(b.width) + "x" +
                     std::to_string(b.height) + ")");
  if (!(ppd > 0) || !std::isfinite(ppd)) throw InputError(std::string(what) + ": pixels per degree must be > 0");
}

double luminance(const glm::vec4& p) {
  const double y = 0.2126 * p.x + 0.7152 * p.y + 0.0722 * p.z;
  return std::isfinite(y) ? std::max(0.0, y) : 0.0;
}

}  // namespace

double flip_ppd(const View& view) { return std::sqrt(view.pixels_per_deg2(view.centre_dir())); }

glm::dvec3 flip_hunt_lab(glm::dvec3 linear_rgb) { return hunt(xyz_to_lab(rgb_to_xyz(glm::clamp(linear_rgb, 0.0, 1.0)))); }

double flip_hyab(glm::dvec3 a, glm::dvec3 b) { return std::abs(a.x - b.x) + std::hypot(a.y - b.y, a.z - b.z); }

double flip_colour_error(double hyab) {
  static const double cmax = std::pow(flip_hyab(flip_hunt_lab({0, 1, 0}), flip_hunt_lab({0, 0, 1})), kQc);
  const double c = std::pow(std::max(0.0, hyab), kQc);
  const double e = c < kPc * cmax ? kPt / (kPc * cmax) * c : kPt + (c - kPc * cmax) / (cmax - kPc * cmax) * (1.0 - kPt);
  return std::min(1.0, e);
}

std::vector<float> ldr_flip(const Image& test, const Image& reference, double ppd) {
  require_inputs(test, reference, ppd, "ldr_flip");
  const std::vector<glm::dvec3> lr = filtered_hunt_lab(reference, ppd), lt = filtered_hunt_lab(test, ppd);
  const Features fr = features(reference, ppd), ft = features(test, ppd);
  std::vector<float> out(lr.size());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double ec = flip_colour_error(flip_hyab(lr[i], lt[i]));
    const double df = std::max(std::abs(fr.edge[i] - ft.edge[i]), std::abs(fr.point[i] - ft.point[i]));
    const double ef = std::pow(std::min(1.0, df / std::numbers::sqrt2), kQf);
    out[i] = float(std::pow(ec, 1.0 - ef));
  }
  return out;
}

double flip_neighbour_weight(double ppd) {
  const double pi = std::numbers::pi, x = 1.0 / ppd;
  return std::exp(-pi * pi * x * x / kCsfMaxB);
}

int flip_support_px(double ppd) { return std::max(csf_radius(ppd), feature_radius(ppd)); }

HdrFlip hdr_flip_exposures(const Image& reference, const std::vector<bool>& valid) {
  if (reference.pixels.empty()) throw InputError("hdr_flip: empty reference image");
  if (!valid.empty() && valid.size() != reference.pixels.size())
    throw InputError("hdr_flip: the valid-pixel mask's size differs from the reference's");
  std::vector<double> y;
  y.reserve(reference.pixels.size());
  for (std::size_t i = 0; i < reference.pixels.size(); ++i)
    if (valid.empty() || valid[i]) y.push_back(luminance(reference.pixels[i]));
  if (y.empty()) throw InputError("hdr_flip: the reference has no valid pixel");
  const double ymax = *std::max_element(y.begin(), y.end());
  HdrFlip h;
  h.exposures = 2;
  if (!(ymax > 0)) return h;  // black reference: one exposure is as good as any
  auto mid = y.begin() + std::ptrdiff_t(y.size() / 2);
  std::nth_element(y.begin(), mid, y.end());
  double ymed = *mid;
  if (!(ymed > 0)) {
    ymed = ymax;
    for (double v : y)
      if (v > 0) ymed = std::min(ymed, v);
  }
  const double x = aces_inverse(0.85);
  h.start_exposure = std::log2(x / ymax);
  h.stop_exposure = std::log2(x / ymed);
  h.exposures = std::max(2, int(std::ceil(h.stop_exposure - h.start_exposure)));
  return h;
}

HdrFlip hdr_flip(const Image& test, const Image& reference, double ppd, const std::vector<bool>& valid) {
  require_inputs(test, reference, ppd, "hdr_flip");
  HdrFlip h = hdr_flip_exposures(reference, valid);
  h.error.assign(reference.pixels.size(), 0.0f);
  for (int i = 0; i < h.exposures; ++i) {
    const double c = h.start_exposure + i * (h.stop_exposure - h.start_exposure) / (h.exposures - 1);
    const std::vector<float> e = ldr_flip(tonemap_linear(test, c), tonemap_linear(reference, c), ppd);
    for (std::size_t k = 0; k < e.size(); ++k) h.error[k] = std::max(h.error[k], e[k]);
  }
  return h;
}

}  // namespace fovea::core
