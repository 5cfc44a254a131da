// Angular Visual-Polar sampling (docs/visual-polar.md; Koskela et al. 2019, "Foveated
// real-time path tracing in Visual-Polar space", P5 §3.2, made angular and derived):
//   σ(e)  = min(κ·σ_disp, σ0·a(e)),  a(e) = m(max(e − s, 0))^γ        target samples/deg²
//   H(e)  = min(N_φ, circ(e)·√σ(e)),  circ(e) = 360°·sin e            rows per column
//   columns: each column's ring holds exactly H_i samples of σ, i.e.
//            ∫_{e_i}^{e_i+1} σ(e)·circ(e) de = H_i                    (density exact per column)
//   N_φ = max_e circ(e)·√(σ(e)/A),  N_ρ from the budget at a centred gaze (fixed per session);
//   per frame σ0 is re-solved so that the N_ρ columns reach E, the farthest frustum point.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "distribution_impl.hpp"
#include "fovea/core/acuity.hpp"
#include "fovea/core/error.hpp"

namespace fovea::core {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr int kNodes = 16384;       // tabulation of a(e), circ(e) over [0°, 180°]
constexpr double kStep = 180.0 / kNodes;

double circumference_deg(double e) { return 360.0 * std::sin(std::clamp(e, 0.0, 180.0) * kDeg); }

class VisualPolar final : public PolarDistribution {
 public:
  VisualPolar(const View& v, const DistributionParams& p) : PolarDistribution(v, p) {
    a_.resize(kNodes + 1);
    circ_.resize(kNodes + 1);
    for (int k = 0; k <= kNodes; ++k) {
      const double e = k * kStep;
      a_[k] = std::pow(acuity::m(std::max(e - p.margin_deg, 0.0)), p.gamma);
      circ_[k] = circumference_deg(e);
    }
    setup_session();
    set_frame(view_.centre_dir());
  }

  double target_density(glm::dvec3 dir) const override { return sigma(angle_deg(dir, gaze_), sigma0_); }

  double pixels_per_cell(int column, glm::dvec3 dir) const override {
    // Ring solid angle 2π(cos e_i − cos e_i+1) = 4π sin(mid)·sin(half-width) sr (no
    // cancellation for thin rings), shared by the column's rows.
    const double sr = 4 * kPi * std::sin(0.5 * (r_[column] + r_[column + 1]) * kDeg) *
                      std::sin(0.5 * (r_[column + 1] - r_[column]) * kDeg);
    return sr / (kDeg * kDeg) / h_[column] * view_.pixels_per_deg2(dir);
  }

  VisualPolarState state() const { return {sigma0_, sigma_disp_, e_max_}; }

 protected:
  void from_polar(double e, double phi, glm::dvec3& dir, glm::dvec2& px) const override {
    const double se = std::sin(e * kDeg), ce = std::cos(e * kDeg);
    dir = ce * gaze_ + se * (std::cos(phi) * b1_ + std::sin(phi) * b2_);
    px = view_.dir_to_pixel(dir).value_or(glm::dvec2(-1e9));
  }

  bool to_polar(glm::dvec2 px, double& e, double& phi) const override {
    if (!std::isfinite(px.x) || !std::isfinite(px.y)) return false;
    const glm::dvec3 d = view_.pixel_to_dir(px);
    e = angle_deg(d, gaze_);
    phi = std::atan2(glm::dot(d, b2_), glm::dot(d, b1_));
    return true;
  }

  void fill_gpu(shaders::GridParams& g) const override { g.family = shaders::kFamilyAngularPolar; }

  void on_frame() override {
    orthonormal_basis(gaze_, b1_, b2_);
    const double e_max = e_max_ = farthest_view_angle(gaze_);
    sigma_disp_ = fovea_pixel_density(gaze_);
    // Solve σ0 so that the session's N_ρ columns end exactly at e_max (bisection in log σ0;
    // the column count grows with σ0).
    double lo = -30, hi = 30;
    for (int it = 0; it < 56; ++it) {
      const double mid = 0.5 * (lo + hi);
      (columns_needed(std::exp(mid), e_max) < columns_ ? lo : hi) = mid;
    }
    sigma0_ = std::exp(hi);
    build_columns(sigma0_, e_max, columns_, &r_, &h_);
    // The bisection leaves the last boundary within rounding of e_max: cover it exactly.
    r_.back() = std::max(r_.back(), e_max);
    if (params_.staircase) apply_staircase();
    publish_table();
  }

 private:
  double sigma(double e, double s0) const {
    const double a = std::pow(acuity::m(std::max(e - params_.margin_deg, 0.0)), params_.gamma);
    return std::min(params_.cap * sigma_disp_, s0 * a);
  }
  double sigma_node(int k, double s0) const { return std::min(params_.cap * sigma_disp_, s0 * a_[k]); }

  // Prefix table S(e_k) = ∫0^{e_k} σ·circ de with σ·circ linear between nodes, so S is
  // piecewise quadratic and exactly invertible.
  void build_prefix(double s0, double e_max) const {
    const int n = std::min(kNodes, int(std::ceil(e_max / kStep)) + 2);
    f_.resize(size_t(n) + 1);
    s_.resize(size_t(n) + 1);
    f_[0] = 0;
    s_[0] = 0;
    for (int k = 1; k <= n; ++k) {
      f_[k] = sigma_node(k, s0) * circ_[k];
      s_[k] = s_[k - 1] + 0.5 * (f_[k - 1] + f_[k]) * kStep;
    }
  }
  double prefix(double e) const {
    const int n = int(s_.size()) - 1;
    const double x = std::clamp(e / kStep, 0.0, double(n));
    const int k = std::min(int(x), n - 1);
    const double t = (x - k) * kStep;
    const double slope = (f_[k + 1] - f_[k]) / kStep;
    return s_[k] + f_[k] * t + 0.5 * slope * t * t;
  }
  double prefix_inverse(double target) const {
    const int n = int(s_.size()) - 1;
    if (target >= s_[n]) {  // beyond the table: extend with the last density
      const double fl = std::max(f_[n], 1e-300);
      return n * kStep + (target - s_[n]) / fl;
    }
    const int k = std::clamp(int(std::upper_bound(s_.begin(), s_.end(), target) - s_.begin()) - 1, 0, n - 1);
    const double rem = target - s_[k];
    const double slope = (f_[k + 1] - f_[k]) / kStep;
    double t;
    if (std::abs(slope) * kStep < 1e-9 * std::max(f_[k], 1e-300)) {
      t = f_[k] > 0 ? rem / f_[k] : 0;
    } else {  // 0.5·slope·t² + f_k·t − rem = 0, stable root
      const double disc = std::max(f_[k] * f_[k] + 2 * slope * rem, 0.0);
      t = 2 * rem / (f_[k] + std::sqrt(disc));
    }
    return k * kStep + std::clamp(t, 0.0, kStep);
  }

  int rows_at(double e, double s0) const {
    const double h = circumference_deg(e) * std::sqrt(sigma(e, s0));
    return int(std::clamp(std::round(h), 1.0, double(rows_)));
  }

  // March columns outwards from the gaze. Returns the (fractional) number of columns
  // needed to reach e_max; with `out_r`/`out_h` records exactly `limit` columns.
  double build_columns(double s0, double e_max, int limit, std::vector<double>* out_r = nullptr,
                       std::vector<int>* out_h = nullptr) const {
    build_prefix(s0, e_max);
    if (out_r) {
      out_r->assign(1, 0.0);
      out_h->clear();
    }
    double e = 0, s = 0;
    for (int i = 0; i < limit; ++i) {
      // Rows from the column's mid-eccentricity: guess the width from the isotropic
      // spacing, then refine once with the width the rows imply.
      const double sg = std::max(sigma(e, s0), 1e-300);
      const double guess = std::clamp(rows_at(e, s0) / (sg * std::max(circumference_deg(e), 1e-300)), 0.0,
                                      1.0 / std::sqrt(sg));
      int h = rows_at(e + 0.5 * guess, s0);
      double next = prefix_inverse(s + h);
      const int h2 = rows_at(0.5 * (e + next), s0);
      if (h2 != h) {
        h = h2;
        next = prefix_inverse(s + h);
      }
      if (out_r) {
        out_r->push_back(next);
        out_h->push_back(h);
      } else if (next >= e_max) {
        return i + (prefix(e_max) - s) / h;
      }
      e = next;
      s += h;
    }
    return limit + 1.0;  // did not reach e_max within the limit
  }

  double columns_needed(double s0, double e_max) const { return build_columns(s0, e_max, columns_ + 2); }

  // Largest angle from the gaze to the frustum boundary (corners, and the edges sampled
  // for views wider than a hemisphere around the gaze).
  double farthest_view_angle(glm::dvec3 g) const {
    double best = 0;
    for (int edge = 0; edge < 4; ++edge)
      for (int k = 0; k <= 64; ++k) {
        const double t = k / 64.0;
        glm::dvec2 px;
        switch (edge) {
          case 0: px = {t * view_.width(), 0}; break;
          case 1: px = {double(view_.width()), t * view_.height()}; break;
          case 2: px = {t * view_.width(), double(view_.height())}; break;
          default: px = {0, t * view_.height()}; break;
        }
        best = std::max(best, angle_deg(view_.pixel_to_dir(px), g));
      }
    return best;
  }

  // σ_disp: the display's pixel density, maximised over the fovea disk (e <= 5.79° + s,
  // plus 1° so that the fovea edge is inside the capped region) within the frustum, so the
  // fovea gets >= κ samples per pixel even where the tangent projection packs pixels
  // densest (gaze towards the edges).
  double fovea_pixel_density(glm::dvec3 g) const {
    glm::dvec3 b1, b2;
    orthonormal_basis(g, b1, b2);
    const double r = (acuity::kFoveaDeg + params_.margin_deg + 1.0) * kDeg;
    double best = view_.pixels_per_deg2(g);
    for (int k = 0; k < 64; ++k) {
      const double phi = 2 * kPi * k / 64;
      glm::dvec3 d = std::cos(r) * g + std::sin(r) * (std::cos(phi) * b1 + std::sin(phi) * b2);
      if (view_.clamp_to_frustum(d)) best = std::max(best, view_.pixels_per_deg2(d));
    }
    return best;
  }

  void apply_staircase() {
    for (int b = 0; b < columns_; b += 32) {
      const int end = std::min(b + 32, columns_);
      const int h = *std::max_element(h_.begin() + b, h_.begin() + end);
      std::fill(h_.begin() + b, h_.begin() + end, h);
    }
  }

  // N_φ and N_ρ from the budget (docs/visual-polar.md §3): at a centred gaze σ0 is chosen
  // so the disk of radius E holds B samples; N_φ bounds the anisotropy by A at the gazes
  // the grid must serve (centre, edges, corners), N_ρ is the columns that budget needs.
  void setup_session() {
    const double budget = std::max(1.0, params_.budget * view_.width() * view_.height());
    const glm::dvec3 centre = view_.centre_dir();
    auto solve_budget = [&](glm::dvec3 g, double& e_max) {
      sigma_disp_ = fovea_pixel_density(g);
      e_max = farthest_view_angle(g);
      double lo = -30, hi = 30;
      for (int it = 0; it < 56; ++it) {
        const double mid = 0.5 * (lo + hi);
        build_prefix(std::exp(mid), e_max);
        (prefix(e_max) < budget ? lo : hi) = mid;
      }
      return std::exp(hi);
    };
    auto rows_needed = [&](double s0, double e_max) {
      double n = 1;
      for (int k = 0; k <= 2048; ++k) {
        const double e = e_max * k / 2048;
        n = std::max(n, circumference_deg(e) * std::sqrt(sigma(e, s0) / params_.aniso));
      }
      return n;
    };
    double e_centre;
    const double s0 = solve_budget(centre, e_centre);
    const double disp_centre = sigma_disp_;
    rows_ = int(std::min(std::ceil(rows_needed(s0, e_centre) - 1e-9), 1e8));
    // Off-centre gazes re-solve σ0 with the same N_ρ and may need more rows to keep the
    // anisotropy bound; more rows per column in turn mean fewer columns for the budget.
    const glm::dvec2 probes[] = {{0, 0}, {0.5, 0}, {1, 0}, {0, 0.5}, {1, 0.5}, {0, 1}, {0.5, 1}, {1, 1}};
    for (int round = 0; round < 2; ++round) {
      sigma_disp_ = disp_centre;
      columns_ = std::max(1, int(std::ceil(build_columns(s0, e_centre, 1 << 24) - 1e-9)));
      if (columns_ > (1 << 22) || rows_ > (1 << 22))
        throw InputError("visual-polar: grid of " + std::to_string(columns_) + "x" + std::to_string(rows_) +
                         " is too large for this display and budget");
      if (round == 1) break;
      for (const glm::dvec2 q : probes) {
        const glm::dvec3 g = view_.pixel_to_dir({q.x * view_.width(), q.y * view_.height()});
        sigma_disp_ = fovea_pixel_density(g);
        const double e_max = farthest_view_angle(g);
        double lo = -30, hi = 30;
        for (int it = 0; it < 56; ++it) {
          const double mid = 0.5 * (lo + hi);
          (columns_needed(std::exp(mid), e_max) < columns_ ? lo : hi) = mid;
        }
        rows_ = std::max(rows_, int(std::ceil(rows_needed(std::exp(hi), e_max) - 1e-9)));
      }
    }
    sigma_disp_ = disp_centre;
  }

  std::vector<double> a_, circ_;        // per node: a(e), circ(e)
  mutable std::vector<double> f_, s_;   // per node for the current σ0: σ·circ and prefix
  glm::dvec3 b1_{1, 0, 0}, b2_{0, 1, 0};
  double sigma0_ = 1, sigma_disp_ = 1, e_max_ = 0;
};

}  // namespace

std::optional<VisualPolarState> visual_polar_state(const SampleDistribution& d) {
  if (const auto* vp = dynamic_cast<const VisualPolar*>(&d)) return vp->state();
  return std::nullopt;
}

std::unique_ptr<SampleDistribution> make_visual_polar(const View& view, const DistributionParams& p) {
  return std::make_unique<VisualPolar>(view, p);
}

}  // namespace fovea::core
