// Polar grids in the display plane around the gaze pixel:
//  - paper-compatible Visual-Polar (Koskela et al. 2019, P5 §3.2): ρ scaled so the farthest
//    display corner is 80° of the acuity CDF ("dynamic rescaling"); a linear fovea with a
//    triangular clip of the φ axis removing 12% of the grid; the periphery through the P4
//    Eq. 7 inverse-CDF polynomial; grid 853×960 for 1280×1440 at the paper's 39% budget.
//  - log-polar (Meng et al. 2018, "Kernel foveated rendering"): buffer (W/σ)×(H/σ) with
//    σ = 1/√budget (Meng's σ = 1.8 is budget 0.31), r(u) = exp(L·(u/w)^α) with
//    L = ln(farthest corner distance), φ uniform.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "distribution_impl.hpp"
#include "fovea/core/acuity.hpp"

namespace fovea::core {

namespace {

constexpr double kPaperClip = 0.12;              // P5: the clip removes 12% of the grid
constexpr double kPaperFoveaS = 2 * kPaperClip;  // a right-triangle clip over s <= s_f removes s_f / 2

class ScreenPolar final : public PolarDistribution {
 public:
  ScreenPolar(const View& v, const DistributionParams& p) : PolarDistribution(v, p) {
    pack_arcs_ = p.pack;
    if (p.kind == DistributionKind::PaperVisualPolar) {
      // Per-axis scale k with k²·(1 − 12%) = budget (P5: 2/3 per axis at 39%).
      const double k = std::sqrt(p.budget / (1.0 - kPaperClip));
      columns_ = std::max(2, int(std::lround(v.width() * k)));
      rows_ = std::max(1, int(std::lround(v.height() * k)));
    } else {
      const double k = std::sqrt(p.budget);
      columns_ = std::max(1, int(std::lround(v.width() * k)));
      rows_ = std::max(1, int(std::lround(v.height() * k)));
    }
    set_frame(view_.centre_dir());
  }

  double target_density(glm::dvec3 dir) const override {
    const auto px = view_.dir_to_pixel(dir);
    if (!px) return 0;
    const auto g = screen_to_grid(*px);
    if (!g) return 0;
    const int i = std::clamp(int(g->x), 0, columns_ - 1);
    const double area = std::numbers::pi * (r_[i + 1] * r_[i + 1] - r_[i] * r_[i]) * arc_fraction(i);
    return area > 0 ? h_[i] / area * view_.pixels_per_deg2(dir) : 0;
  }

  double pixels_per_cell(int column, glm::dvec3) const override {
    return std::numbers::pi * (r_[column + 1] * r_[column + 1] - r_[column] * r_[column]) * arc_fraction(column) /
           h_[column];
  }

 protected:
  void from_polar(double r, double phi, glm::dvec3& dir, glm::dvec2& px) const override {
    px = gaze_px_ + r * glm::dvec2(std::cos(phi), std::sin(phi));
    dir = view_.pixel_to_dir(px);
  }
  bool to_polar(glm::dvec2 px, double& r, double& phi) const override {
    if (!std::isfinite(px.x) || !std::isfinite(px.y)) return false;
    const glm::dvec2 d = px - gaze_px_;
    r = glm::length(d);
    phi = std::atan2(d.y, d.x);
    return true;
  }
  void fill_gpu(shaders::GridParams& g) const override { g.family = shaders::kFamilyScreenPolar; }

  // The display's edges seen from the gaze pixel: a ring of radius r crosses the edge at
  // distance d where cos(φ − its direction) > d / r.
  double mask_free_radius() const override {
    const auto centre = view_.dir_to_pixel(view_.centre_dir());
    return centre ? mask_free_px_ - glm::length(gaze_px_ - *centre) : -INFINITY;
  }

  // The published grid's samples (the budget), less the lens' hidden share: packed rings
  // take up what the published layout leaves beyond the display's edges.
  double centre_reference(double) const override { return budgeted_samples() * visible_fraction_; }
  double budgeted_samples() const override {
    double rows = 0;
    for (double h : full_) rows += h;
    return rows;
  }

  RingSides view_sides(double r) const override {
    const double w = view_.width(), h = view_.height(), pi = std::numbers::pi;
    const auto t = [r](double d) { return r > 0 ? d / r : INFINITY; };
    return {{{t(gaze_px_.x), pi}, {t(w - gaze_px_.x), 0}, {t(gaze_px_.y), -0.5 * pi}, {t(h - gaze_px_.y), 0.5 * pi}}};
  }

  void on_frame() override {
    gaze_px_ = view_.dir_to_pixel(gaze_).value_or(glm::dvec2(view_.width() * 0.5, view_.height() * 0.5));
    double dmax = 0;
    for (glm::dvec2 c : {glm::dvec2(0, 0), glm::dvec2(view_.width(), 0), glm::dvec2(0, view_.height()),
                         glm::dvec2(view_.width(), view_.height())})
      dmax = std::max(dmax, glm::length(c - gaze_px_));
    dmax = std::max(dmax, 1.0);
    r_.resize(size_t(columns_) + 1);
    h_.resize(size_t(columns_));
    const bool paper = params_.kind == DistributionKind::PaperVisualPolar;
    for (int i = 0; i <= columns_; ++i) {
      const double s = double(i) / columns_;
      if (paper) {
        if (s <= kPaperFoveaS) {
          r_[i] = dmax * (acuity::kFoveaDeg / acuity::kTruncDeg) * (s / kPaperFoveaS);
        } else {
          const double u = acuity::kP4Branch + (s - kPaperFoveaS) / (1 - kPaperFoveaS) * (1 - acuity::kP4Branch);
          r_[i] = dmax * acuity::cdf_inverse_p4(u) / acuity::kTruncDeg;
        }
      } else {
        r_[i] = i == 0 ? 0.0 : std::exp(std::log(dmax) * std::pow(s, params_.logpolar_alpha));
      }
    }
    // The polynomial tops out at 79.97°: stretch the last boundary to the corner.
    r_.back() = std::max(r_.back(), dmax);
    for (int i = 0; i < columns_; ++i) {
      const double s_mid = (i + 0.5) / columns_;
      h_[i] = (paper && s_mid < kPaperFoveaS)
                  ? std::clamp(int(std::lround(rows_ * s_mid / kPaperFoveaS)), 1, rows_)
                  : rows_;
    }
    // The papers' layouts, each ring packed to its arc on the display with its rows scaled
    // so the published grid's samples are traced at every gaze (pack = false: as published).
    full_.assign(h_.begin(), h_.end());
    if (pack_arcs_)
      fit_budget();
    else  // full rings: the layout as published at every gaze
      pack(1.0);
    publish_table();
  }

 private:
  glm::dvec2 gaze_px_{0, 0};
};

}  // namespace

std::unique_ptr<SampleDistribution> make_screen_polar(const View& view, const DistributionParams& p) {
  return std::make_unique<ScreenPolar>(view, p);
}

}  // namespace fovea::core
