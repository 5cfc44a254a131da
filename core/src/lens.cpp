#include "fovea/core/lens.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"

namespace fovea::core {

namespace {

constexpr const char* kChannelName[3] = {"red", "green", "blue"};

double profile(const Lens::Channel& c, double r) {
  const auto& k = c.k;
  if (c.vive_profile) {
    const double r2 = r * r;
    return 1.0 / (1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[2]))) + k[3];
  }
  return k[0] + r * (k[1] + r * (k[2] + r * (k[3] + r * k[4])));
}

double profile_derivative_of_radial(const Lens::Channel& c, double r) {
  const auto& k = c.k;
  if (c.vive_profile) {
    // g = r/D + k4 r with D = 1 + k1 r² + k2 r⁴ + k3 r⁶:  g' = (D − r·D')/D² + k4.
    const double r2 = r * r;
    const double D = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[2]));
    const double rDp = r2 * (2 * k[0] + r2 * (4 * k[1] + r2 * 6 * k[2]));
    return (D - rDp) / (D * D) + k[3];
  }
  return k[0] + r * (2 * k[1] + r * (3 * k[2] + r * (4 * k[3] + r * 5 * k[4])));
}

// Where the radial map is usable: positive denominator (Vive) and increasing.
bool usable(const Lens::Channel& c, double r) {
  if (c.vive_profile) {
    const double r2 = r * r;
    const double D = 1.0 + r2 * (c.k[0] + r2 * (c.k[1] + r2 * c.k[2]));
    if (!(D > 1e-9)) return false;
  }
  const double d = profile_derivative_of_radial(c, r);
  return std::isfinite(d) && d > 0;
}

// First radius in (0, r_max] where the map stops being usable, or r_max. A dense scan then
// bisection: wiggles narrower than r_max/4096 could slip through, far below a pixel here.
double usable_limit(const Lens::Channel& c, double r_max) {
  constexpr int kSteps = 4096;
  double prev = 0;
  for (int i = 1; i <= kSteps; ++i) {
    const double r = r_max * i / kSteps;
    if (!usable(c, r)) {
      double lo = prev, hi = r;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (usable(c, mid) ? lo : hi) = mid;
      }
      return lo;
    }
    prev = r;
  }
  return r_max;
}

}  // namespace

Lens::Lens(const LensParams& p, const View& view, Eye eye, const std::string& name)
    : view_(view), kind_(p.kind) {
  const double mirror = eye == Eye::Right ? -1.0 : 1.0;
  const double W = view.width(), H = view.height();
  double cutoff = std::numeric_limits<double>::infinity();
  for (int c = 0; c < 3; ++c) {
    Channel& ch = ch_[c];
    switch (p.kind) {
      case LensModelKind::None:
        ch.display_centre = ch.source_centre = {0.5, 0.5};
        ch.to_radial = ch.from_radial = {1, 1};
        break;
      case LensModelKind::Vive: {
        // t = (2u−1, (2v−1)/a) − C  ⇔  t = (uv − ((1+Cx)/2, (1+a·Cy)/2)) ⊙ (2, 2/a);
        // uv' = ½ + (t·d + C) ⊙ (f, f·a)  ⇔  uv' = (½ + Cx·f, ½ + Cy·f·a) + (f, f·a) ⊙ t·d.
        const ViveLens& v = p.vive;
        const double a = v.aspect, f = 0.5 / (1.0 + v.grow);
        const glm::dvec2 C(mirror * v.channel[c].centre.x, v.channel[c].centre.y);
        ch.display_centre = {(1 + C.x) / 2, (1 + a * C.y) / 2};
        ch.to_radial = {2, 2 / a};
        ch.source_centre = {0.5 + C.x * f, 0.5 + C.y * f * a};
        ch.from_radial = {f, f * a};
        ch.vive_profile = true;
        ch.k = {v.channel[c].k[0], v.channel[c].k[1], v.channel[c].k[2], v.channel[c].k[3], 0};
        if (v.r2_cutoff > 0) cutoff = std::sqrt(v.r2_cutoff);
        break;
      }
      case LensModelKind::Panotools: {
        // Pixels: p = (uv⊙V − L)/s, uv' = (p·f(ρ)·s·ab + L)/V with V = (W, H), L = centre⊙V,
        // s = scale·W  ⇔  to_radial = V/s, from_radial = ab·s/V, both centres = centre.
        const PanotoolsLens& t = p.panotools;
        const glm::dvec2 centre(eye == Eye::Right ? 1.0 - t.centre.x : t.centre.x, t.centre.y);
        const double s = t.scale * W;
        ch.display_centre = ch.source_centre = centre;
        ch.to_radial = {W / s, H / s};
        ch.from_radial = glm::dvec2(s / W, s / H) * t.aberration[c];
        ch.k = t.k;
        if (t.cutoff > 0) cutoff = t.cutoff;
        break;
      }
    }
    // The largest radius on the panel: its farthest corner from this channel's centre.
    double r_panel = 0;
    for (glm::dvec2 corner : {glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(0, 1), glm::dvec2(1, 1)})
      r_panel = std::max(r_panel, glm::length((corner - ch.display_centre) * ch.to_radial));
    if (p.kind == LensModelKind::None) {
      ch.r_edge = 2 * r_panel;
      continue;
    }
    const double r_scan = 1.5 * r_panel;
    const double limit = usable_limit(ch, r_scan);
    if (limit < 0.02 * r_panel)
      throw InputError(name + " (" + eye_name(eye) + " eye, " + kChannelName[c] +
                       "): the radial map stops increasing at r = " + std::to_string(limit) +
                       ", leaving no usable lens area (check the coefficients)");
    if (limit < r_panel)
      notes_.push_back(name + " (" + eye_name(eye) + " eye, " + kChannelName[c] +
                       "): the radial map stops increasing at r = " + std::to_string(limit) +
                       " (" + std::to_string(int(std::lround(100 * limit / r_panel))) +
                       "% of the panel corner's radius); everything beyond is outside the lens");
    ch.r_edge = std::min(limit, cutoff);
  }
  if (p.kind != LensModelKind::None) check_visible_area(name, eye);
}

// Coefficients far from any real lens (k = 1e30) keep the radial map increasing but send
// every panel pixel's source outside the FOV: an all-black panel. Refused, on a coarse grid
// of panel positions (the per-pixel mask is the hidden area's job, hidden_area.hpp).
void Lens::check_visible_area(const std::string& name, Eye eye) const {
  constexpr int kGrid = 64;
  int shown = 0;
  for (int j = 0; j < kGrid; ++j)
    for (int i = 0; i < kGrid; ++i) {
      const LensSample s = forward({(i + 0.5) / kGrid, (j + 0.5) / kGrid});
      bool ok = s.within_lens;
      for (const glm::dvec2& t : s.tangent)
        ok = ok && t.x >= view_.tan_left() && t.x <= view_.tan_right() && t.y >= view_.tan_down() && t.y <= view_.tan_up();
      shown += ok;
    }
  if (shown < kMinVisibleFraction * kGrid * kGrid)
    throw InputError(name + " (" + eye_name(eye) + " eye): " + std::to_string(shown) + " of " +
                     std::to_string(kGrid * kGrid) + " panel positions show the field of view, below the minimum of " +
                     std::to_string(int(kMinVisibleFraction * 100)) +
                     "%: the lens leaves no usable area (check lens.k, lens.scale and the FOV)");
}

Lens Lens::for_eye(const DisplayPreset& d, Eye eye) {
  return Lens(d.lens, d.view(eye), eye, (d.origin.empty() ? d.name : d.origin) + ": lens");
}

glm::dvec2 Lens::uv_to_tangent(glm::dvec2 uv) const {
  return {view_.tan_left() + uv.x * (view_.tan_right() - view_.tan_left()),
          view_.tan_up() - uv.y * (view_.tan_up() - view_.tan_down())};
}

glm::dvec2 Lens::tangent_to_uv(glm::dvec2 t) const {
  return {(t.x - view_.tan_left()) / (view_.tan_right() - view_.tan_left()),
          (view_.tan_up() - t.y) / (view_.tan_up() - view_.tan_down())};
}

double Lens::radial(int c, double r) const { return r * profile(ch_[c], r); }
double Lens::radial_derivative(int c, double r) const { return profile_derivative_of_radial(ch_[c], r); }

glm::dvec2 Lens::source_uv(int c, glm::dvec2 uv) const {
  const Channel& ch = ch_[c];
  const glm::dvec2 t = (uv - ch.display_centre) * ch.to_radial;
  const double r = glm::length(t);
  // Past the edge the profile may have a pole or turn back: continue with the edge's scale.
  const double scale = profile(ch, std::min(r, ch.r_edge));
  return ch.source_centre + ch.from_radial * t * scale;
}

LensSample Lens::forward(glm::dvec2 uv) const {
  LensSample s;
  for (int c = 0; c < 3; ++c) {
    const Channel& ch = ch_[c];
    const double r = glm::length((uv - ch.display_centre) * ch.to_radial);
    if (!(r <= ch.r_edge)) s.within_lens = false;
    s.tangent[c] = uv_to_tangent(source_uv(c, uv));
  }
  return s;
}

std::optional<glm::dvec2> Lens::inverse(int c, glm::dvec2 tangent) const {
  if (!std::isfinite(tangent.x) || !std::isfinite(tangent.y)) return std::nullopt;
  const Channel& ch = ch_[c];
  const glm::dvec2 w = (tangent_to_uv(tangent) - ch.source_centre) / ch.from_radial;  // = t·R(r)
  const double rho = glm::length(w);
  if (rho == 0) return ch.display_centre;
  // Solve g(r) = r·R(r) = ρ on [0, r_edge], where g increases from 0.
  const double g_edge = radial(c, ch.r_edge);
  if (rho > g_edge) return std::nullopt;
  double lo = 0, hi = ch.r_edge;
  double r = std::clamp(rho / profile(ch, 0), lo, hi);
  for (int it = 0; it < 100; ++it) {
    const double f = radial(c, r) - rho;
    if (f == 0) break;
    (f < 0 ? lo : hi) = r;
    const double d = profile_derivative_of_radial(ch, r);
    double next = r - f / d;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // Newton left the bracket
    if (std::abs(next - r) <= 1e-15 * (1 + r)) {
      r = next;
      break;
    }
    r = next;
  }
  return ch.display_centre + (w * (r / rho)) / ch.to_radial;
}

}  // namespace fovea::core
