// Angular Visual-Polar sampling (docs/visual-polar.md; Koskela et al. 2019, "Foveated
// real-time path tracing in Visual-Polar space", P5 §3.2, made angular and derived):
//   σ(e)  = min(κ·D(e), σ0·a(e)),  a(e) = m(max(e − s, 0))^γ           target samples/deg²
//   D(e)  = σ_disp, the display's densest pixels in the fovea disk; on a view where κ·σ_disp
//           over the whole view cannot pay the budget at some gaze (a wide view, whose
//           periphery is denser than its fovea): σ_disp out to the fovea disk, then the
//           densest pixels any ring out to e has, so κ samples per pixel where the pixels are
//   H(e)  = min(N_φ, circ(e)·√σ(e)),  circ(e) = 360°·sin e            rows per column
//   columns: each column's ring holds exactly H_i samples of σ, i.e.
//            ∫_{e_i}^{e_i+1} σ(e)·circ(e) de = H_i                    (density exact per column)
//   N_φ = max_e circ(e)·√(σ(e)/A),  N_ρ from the budget at a centred gaze (fixed per session);
//   per frame σ0 is re-solved so that the N_ρ columns reach E, the farthest frustum point.
// Packing: a ring the view frustum cuts keeps only the rows of its visible arc (rows ·
// arc / 2π, same spacing along φ), so the budget buys a higher σ0 (docs/visual-polar.md).
// The σ0 equations are solved by a safeguarded secant in log σ0, warm-started per frame
// from the previous frame's root and slope; the 56-step bisection it replaced stays
// selectable as the reference the tests and bench/grid_bench.cpp compare against.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "distribution_impl.hpp"
#include "fovea/core/acuity.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/visual_polar_testing.hpp"

namespace fovea::core {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr int kNodes = 16384;       // tabulation of a(e), circ(e) over [0°, 180°]
constexpr double kStep = 180.0 / kNodes;

constexpr double kLogLo = -30, kLogHi = 30;  // search range of log σ0
// The per-frame solve stops when the N_ρ columns end within 10⁻⁹ of a column of E.
constexpr double kColumnTol = 1e-9;

double circumference_deg(double e) { return 360.0 * std::sin(std::clamp(e, 0.0, 180.0) * kDeg); }

// Both solvers take g(x, d) of x = log σ0, which returns g and sets d to its derivative
// where g is smooth around x (NaN if unknown).

// The reference solver: the root of an increasing g on [kLogLo, kLogHi] by 56 bisection
// steps, returning the upper end (g >= 0).
template <class G>
double bisect(G&& g) {
  double lo = kLogLo, hi = kLogHi, d;
  for (int it = 0; it < 56; ++it) {
    const double mid = 0.5 * (lo + hi);
    (g(mid, d) < 0 ? lo : hi) = mid;
  }
  return hi;
}

// Root of an increasing g near x0 (|g| <= tol), given `slope`, an estimate of g' over
// the distance to the root. g may be smooth only in pieces `piece` long with small jumps
// between them: steps longer than that are secant steps (the first one Newton's with
// `slope`), shorter ones Newton steps with the piece's own derivative. Until the root is
// bracketed a step that does not halve |g| makes the next one at least twice as long;
// once bracketed a step leaving the bracket, or three steps that do not halve it, fall
// back to bisection, so jumps or flat parts cost at most what bisection would. On return
// `slope` is the first secant's, the scale of a frame's gaze change, for the next start.
template <class G>
double solve_increasing(G&& g, double x0, double& slope, double tol, double piece = INFINITY) {
  double lo = kLogLo, hi = kLogHi;  // g(lo) < 0 <= g(hi) where evaluated
  bool has_lo = false, has_hi = false;
  double x = std::clamp(x0, kLogLo, kLogHi), xp = x, gp = 0;
  double s = std::isfinite(slope) && slope > 0 ? slope : 1.0;
  double width = hi - lo;  // bracket width when the halving rule last checked it
  int bracketed_steps = 0;
  for (int it = 0; it < 200; ++it) {
    double d = NAN;
    const double gx = g(x, d);
    if (it > 0 && gx != gp) {
      const double secant = (gx - gp) / (x - xp);
      if (secant > 0 && std::isfinite(secant)) {
        s = secant;
        if (it == 1) slope = secant;
      }
    }
    if (std::abs(gx) <= tol) return x;
    (gx < 0 ? lo : hi) = x;
    (gx < 0 ? has_lo : has_hi) = true;
    if (hi - lo <= 1e-15 * std::max(1.0, std::abs(x))) break;
    double next = x - gx / s;
    if (d > 0 && std::abs(gx) < piece * d) next = x - gx / d;
    if (!(has_lo && has_hi)) {
      if (it > 0 && std::abs(gx) > 0.5 * std::abs(gp) && std::abs(next - x) < 2 * std::abs(x - xp))
        next = x + std::copysign(2 * std::abs(x - xp), -gx);
      next = std::clamp(next, kLogLo, kLogHi);
      if (next == x) break;  // no root in the range: stay at its end
    } else {
      bool bisect_now = !(next > lo && next < hi);
      if (++bracketed_steps % 3 == 0) {
        bisect_now = bisect_now || hi - lo > 0.5 * width;
        width = hi - lo;
      }
      if (bisect_now) next = 0.5 * (lo + hi);
    }
    xp = x;
    gp = gx;
    x = next;
  }
  return has_hi ? hi : x;
}

// The frustum's sides seen from the gaze g (basis b1, b2): each side n·d >= 0 (n inward;
// n·g >= 0 as the gaze is inside) hides on d = cos e·g + sin e·(cos φ·b1 + sin φ·b2) the φ
// with cos(φ − α) < −t, t = cos e·(n·g) / (sin e·|(n·b1, n·b2)|), α = atan2(n·b2, n·b1):
// an arc centred at α + π of half-width acos t. Per side: n·g, |(n·b1, n·b2)| and α + π.
struct FrustumSide {
  double along, across, hidden_centre;
};
std::array<FrustumSide, 4> frustum_sides(const View& v, glm::dvec3 g, glm::dvec3 b1, glm::dvec3 b2) {
  const glm::dvec3 normals[] = {
      {1, 0, v.tan_left()}, {-1, 0, -v.tan_right()}, {0, 1, v.tan_down()}, {0, -1, -v.tan_up()}};
  std::array<FrustumSide, 4> sides;
  for (int k = 0; k < 4; ++k) {
    const double a = glm::dot(normals[k], b1), b = glm::dot(normals[k], b2);
    sides[size_t(k)] = {glm::dot(normals[k], g), std::hypot(a, b), std::atan2(b, a) + kPi};
  }
  return sides;
}

class VisualPolar final : public PolarDistribution {
 public:
  VisualPolar(const View& v, const DistributionParams& p, const ViewMask* visibility) : PolarDistribution(v, p) {
    if (visibility) adopt_mask(*visibility);  // the layout's budget: the pixels it leaves
    a_.resize(kNodes + 1);
    circ_.resize(kNodes + 1);
    for (int k = 0; k <= kNodes; ++k) {
      const double e = k * kStep;
      a_[k] = acuity_term(e);
      circ_[k] = circumference_deg(e);
    }
    pack_arcs_ = packing();
    setup_session();
    session_ = {sigma0_, slope_, e_max_, r_};
    set_frame(view_.centre_dir());
  }

  // σ at the budget's scale, less where the grid's N_φ rows cannot hold a ring's share.
  double target_density(glm::dvec3 dir) const override {
    const double e = angle_deg(dir, gaze_);
    const auto it = std::upper_bound(r_.begin(), r_.end(), e);
    const size_t i = size_t(std::clamp(int(it - r_.begin()) - 1, 0, columns_ - 1));
    return sigma(e, row_scale_ * sigma0_) * (i < rows_kept_.size() ? rows_kept_[i] : 1.0);
  }

  double pixels_per_cell(int column, glm::dvec3 dir) const override {
    // Ring solid angle 2π(cos e_i − cos e_i+1) = 4π sin(mid)·sin(half-width) sr (no
    // cancellation for thin rings), shared by the column's rows.
    const double sr = 4 * kPi * std::sin(0.5 * (r_[column] + r_[column + 1]) * kDeg) *
                      std::sin(0.5 * (r_[column + 1] - r_[column]) * kDeg);
    return sr * arc_fraction(column) / (kDeg * kDeg) / h_[column] * view_.pixels_per_deg2(dir);
  }

  VisualPolarState state() const { return {sigma0_, row_scale_, sigma_disp_, e_max_, evaluations_, ring_cap_}; }
  void set_reference_solve(bool on) {
    reference_solve_ = on;
    on_frame();
  }

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

  double mask_free_radius() const override { return mask_free_deg_ - angle_deg(gaze_, view_.centre_dir()); }

  RingSides view_sides(double e) const override {
    const double se = std::sin(e * kDeg), ce = std::cos(e * kDeg);
    RingSides sides;
    for (size_t k = 0; k < 4; ++k) {
      const double across = se * sides_[k].across;
      sides[k] = {across > 0 ? ce * sides_[k].along / across : INFINITY, sides_[k].hidden_centre};
    }
    return sides;
  }

  // Density c·σ0·a(e) with the columns held: the rows follow the density's change at the
  // column's middle, so the capped fovea keeps its rows (κ samples per pixel at most).
  // Never fewer rows than the anisotropy bound A asks of the column.
  double scaled_rows(int i, double c) const override {
    if (c == 1.0) return full_[size_t(i)];
    const size_t k = size_t(i);
    // A budget below the layout's (under a lens) is taken from beyond the fovea disk only.
    if (c < 1.0 && r_[k] < fovea_disk_deg()) return full_[k];
    const double a = column_acuity_[k], cap = cap_at(0.5 * (r_[k] + r_[k + 1]));
    const double rows = full_[k] * std::min(cap, c * sigma0_ * a) / std::max(std::min(cap, sigma0_ * a), 1e-300);
    const double least = circumference_deg(0.5 * (r_[k] + r_[k + 1])) / (params_.aniso * (r_[k + 1] - r_[k]));
    return std::max(rows, std::min(least, full_[k]));
  }

  // The budget is its fraction of the pixels the view (and a mask) leaves visible, as for
  // the raster kinds; the session's layout traces that at the centred gaze (setup_session),
  // under the mask given to make_distribution. A mask set later takes the layout's surplus
  // back from the periphery (c < 1 on the uncapped columns' rows, scaled_rows): the layout
  // solved for the whole view loses fewer samples to a lens' hidden periphery than pixels
  // (its density falls with eccentricity). Unpacked full rings (a layout study's option,
  // `pack = false`) keep their own count without a mask: the budget is their rings'.
  double centre_reference(double own) const override {
    if (!packing() && !(visible_fraction_ < 1)) return own;
    return std::max(1.0, params_.budget * view_.width() * view_.height() * visible_fraction_);
  }
  // What make_distribution checks: the samples traced on the view at the centred gaze over
  // the view's share the mask leaves (the reference), not the rows the grid holds (an outer
  // column's ring reaches past the view's edges); unpacked full rings, their rows.
  double budgeted_samples() const override {
    return packing() && centre_traced_ > 0 ? centre_traced_ / visible_fraction_ : grid_samples();
  }

  // The per-frame solve starts from the previous frame's root; its several close roots
  // (docs/visual-polar.md) make the grid depend on that history in the last bits.
  void forget_frames() override {
    sigma0_ = session_.sigma0;
    slope_ = session_.slope;
    e_max_ = session_.e_max;
    r_ = session_.r;
  }

  void on_frame() override {
    orthonormal_basis(gaze_, b1_, b2_);
    sides_ = frustum_sides(view_, gaze_, b1_, b2_);
    const double previous_e_max = e_max_;
    const double e_max = e_max_ = farthest_view_angle(gaze_);
    set_density_cap(gaze_);
    // Warm start: the previous root, moved by the columns the change of e_max adds at the
    // previous outermost column's width (relative to N_ρ: the solve is in log columns).
    const double last_width = r_.size() > 1 ? r_.back() - r_[r_.size() - 2] : 0;
    double x0 = std::log(sigma0_);
    if (previous_e_max > 0 && last_width > 0)
      x0 -= (e_max - previous_e_max) / last_width / columns_ / slope_;
    sigma0_ = std::exp(solve_columns(e_max, x0));
    // The solve leaves the last boundary within 10⁻⁹ of a column of e_max: cover it exactly.
    r_.back() = std::max(r_.back(), e_max);
    // The budget at this gaze: rows scaled so the traced samples meet it (P5's staircase
    // keeps its layout, as the option of the layout study it is).
    if (params_.staircase) apply_staircase();
    full_.assign(h_.begin(), h_.end());
    column_acuity_.resize(h_.size());
    for (size_t i = 0; i < h_.size(); ++i) column_acuity_[i] = acuity_term(0.5 * (r_[i] + r_[i + 1]));
    row_scale_ = params_.staircase ? 1.0 : fit_budget();
    if (params_.staircase) pack(1.0);
    publish_table();
  }

 private:
  // a(e) = m(max(e − s, 0))^γ (pow(x, 1) == x, so γ = 1 skips it exactly).
  double acuity_term(double e) const {
    const double m = acuity::m(std::max(e - params_.margin_deg, 0.0));
    return params_.gamma == 1.0 ? m : std::pow(m, params_.gamma);
  }
  double sigma(double e, double s0) const { return std::min(cap_at(e), s0 * acuity_term(e)); }
  double sigma_node(int k, double s0) const { return std::min(cap_[size_t(k)], s0 * a_[size_t(k)]); }
  // κ·D(e) (the header), per node; linear between nodes.
  double cap_at(double e) const {
    const double x = std::clamp(e / kStep, 0.0, double(kNodes));
    const int k = std::min(int(x), kNodes - 1);
    return cap_[size_t(k)] + (x - k) * (cap_[size_t(k) + 1] - cap_[size_t(k)]);
  }

  // Prefix table S(e_k) = ∫0^{e_k} σ·circ de with σ·circ linear between nodes, so S is
  // piecewise quadratic and exactly invertible.
  // `weight` (per node, optional) scales σ·circ: the visible fraction of each ring.
  void build_prefix(double s0, double e_max, const std::vector<double>* weight = nullptr) const {
    const int n = std::min(kNodes, int(std::ceil(e_max / kStep)) + 2);
    f_.resize(size_t(n) + 1);
    s_.resize(size_t(n) + 1);
    f_[0] = 0;
    s_[0] = 0;
    for (int k = 1; k <= n; ++k) {
      f_[k] = sigma_node(k, s0) * circ_[k] * (weight ? (*weight)[size_t(k)] : 1.0);
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
  // `from`: a node at or below the answer (the column's inner edge): the search gallops
  // outwards from it (a column spans a few nodes) rather than bisecting the whole table,
  // and finds the same node.
  double prefix_inverse(double target, int from = 0) const {
    const int n = int(s_.size()) - 1;
    if (target >= s_[n]) {  // beyond the table: extend with the last density
      const double fl = std::max(f_[n], 1e-300);
      return n * kStep + (target - s_[n]) / fl;
    }
    int lo = from > 0 && from < n && s_[from] <= target ? from : 0, step = 1;
    while (lo + step <= n && s_[lo + step] <= target) {
      lo += step;
      step *= 2;
    }
    const auto end = s_.begin() + std::min(lo + step, n + 1);
    const int k = std::clamp(int(std::upper_bound(s_.begin() + lo, end, target) - s_.begin()) - 1, 0, n - 1);
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

  int rows_for(double circ, double sg) const {
    return int(std::clamp(std::round(circ * std::sqrt(sg)), 1.0, double(rows_)));
  }
  int rows_at(double e, double s0) const { return rows_for(circumference_deg(e), sigma(e, s0)); }

  // d S(e)/d log σ0 (to within one node): the prefix without its capped part, σ0·a >=
  // κD on [0, e_K) as a(e) is non-increasing and D(e) non-decreasing.
  double prefix_dlog(double s0, double e) const {
    int k = 0;
    for (int n = int(s_.size()); k < n && s0 * a_[size_t(k)] >= cap_[size_t(k)];) ++k;
    return k * kStep >= e ? 0.0 : prefix(e) - s_[std::min(k, int(s_.size()) - 1)];
  }

  // March columns outwards from the gaze until they pass e_max (and at least `record`
  // columns are in r, h when given; r starts at 0) or `limit` columns. Returns the
  // (fractional) number of columns needed to reach e_max; beyond `limit` it is continued
  // with the last column's rows, so the solves see an increasing function, not a plateau.
  // `dlog`, when given, receives its derivative in log σ0 with the rows held: the column
  // count is i + (S(e_max) − Σ rows)/rows_i, so only S(e_max) moves.
  double march(double s0, double e_max, int limit, int record = 0, std::vector<double>* r = nullptr,
               std::vector<int>* h = nullptr, double* dlog = nullptr) const {
    build_prefix(s0, e_max);
    if (r) {
      r->assign(1, 0.0);
      h->clear();
    }
    double e = 0, s = 0, needed = INFINITY;
    int rows = 1;
    for (int i = 0; i < limit; ++i) {
      // Rows from the column's mid-eccentricity: guess the width from the isotropic
      // spacing, then refine once with the width the rows imply.
      const double circ = circumference_deg(e), sg0 = sigma(e, s0);
      const double sg = std::max(sg0, 1e-300);
      const double guess =
          std::clamp(rows_for(circ, sg0) / (sg * std::max(circ, 1e-300)), 0.0, 1.0 / std::sqrt(sg));
      rows = rows_at(e + 0.5 * guess, s0);
      const int from = e < 180.0 ? int(e / kStep) - 1 : kNodes;  // e runs past the table for tiny σ0
      double next = prefix_inverse(s + rows, from);
      const int rows2 = rows_at(0.5 * (e + next), s0);
      if (rows2 != rows) {
        rows = rows2;
        next = prefix_inverse(s + rows, from);
      }
      if (r) {
        r->push_back(next);
        h->push_back(rows);
      }
      if (next >= e_max && !std::isfinite(needed)) {
        needed = i + (prefix(e_max) - s) / rows;
        if (dlog) *dlog = prefix_dlog(s0, e_max) / rows;
      }
      if (std::isfinite(needed) && i + 1 >= record) break;
      e = next;
      s += rows;
    }
    return std::isfinite(needed) ? needed : limit + (prefix(e_max) - s) / rows;
  }

  // log σ0 such that the N_ρ columns end at e_max (the column count grows with σ0),
  // starting from x0; leaves the root's column table (N_ρ columns) in r_, h_.
  double solve_columns(double e_max, double x0) {
    evaluations_ = 0;
    double kept = NAN;
    auto g = [&](double x, double& d) {
      ++evaluations_;
      kept = x;
      // In log columns: the count grows like √σ0, so g is close to linear in x.
      const double n = std::max(march(std::exp(x), e_max, columns_ + 2, columns_, &r_, &h_, &d), 1e-12);
      d /= n;
      return std::log(n / columns_);
    };
    // A column's rows change where √σ0 grows by 1/rows, so over the grid every ~2/samples
    // in log σ0; between those points the rows are constant and g smooth. The pieces are
    // taken as 1/(N_ρ·N_φ), about half that.
    const double piece = 1.0 / (double(columns_) * rows_);
    const double x =
        reference_solve_ ? bisect(g) : solve_increasing(g, x0, slope_, kColumnTol / columns_, piece);
    if (double d; kept != x) g(x, d);
    r_.resize(size_t(columns_) + 1);
    h_.resize(size_t(columns_));
    return x;
  }

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

  // σ_disp and the cap per node (the header's D(e)) for gaze g: κ·σ_disp everywhere, or with
  // ring_cap_ κ·σ_disp out to the fovea disk and beyond it the densest visible pixels of
  // each ring (48 directions on 96 rings out to the farthest view angle, linear between
  // them), never less than nearer rings'.
  void set_density_cap(glm::dvec3 g) {
    sigma_disp_ = fovea_pixel_density(g);
    if (!ring_cap_) {  // one cap: rewritten only when it changes
      const double cap = params_.cap * sigma_disp_;
      if (cap_.empty() || cap_[0] != cap) cap_.assign(size_t(kNodes) + 1, cap);
      return;
    }
    cap_.resize(size_t(kNodes) + 1);
    const double fovea = fovea_disk_deg(), e_far = farthest_view_angle(g);
    glm::dvec3 b1, b2;
    orthonormal_basis(g, b1, b2);
    constexpr int kRings = 96, kDirs = 48;
    std::array<double, kRings + 1> ring{};
    double most = sigma_disp_;
    for (int j = 0; j <= kRings; ++j) {
      const double e = fovea + (e_far - fovea) * j / kRings;
      if (e > fovea) {
        const double se = std::sin(e * kDeg), ce = std::cos(e * kDeg);
        for (int k = 0; k < kDirs; ++k) {
          const double phi = 2 * kPi * k / kDirs;
          const glm::dvec3 d = ce * g + se * (std::cos(phi) * b1 + std::sin(phi) * b2);
          if (view_.dir_to_pixel(d)) most = std::max(most, view_.pixels_per_deg2(d));
        }
      }
      ring[size_t(j)] = most;
    }
    for (int k = 0; k <= kNodes; ++k) {
      const double e = k * kStep;
      double d = sigma_disp_;
      if (e > fovea && e_far > fovea) {
        const double x = std::min((e - fovea) / (e_far - fovea) * kRings, double(kRings));
        const int j = std::min(int(x), kRings - 1);
        d = ring[size_t(j)] + (x - j) * (ring[size_t(j) + 1] - ring[size_t(j)]);
      }
      cap_[size_t(k)] = params_.cap * d;
    }
  }

  // σ_disp: the display's pixel density, maximised over the fovea disk (e <= 5.79° + s,
  // plus 1° so that the fovea edge is inside the capped region) within the frustum, so the
  // fovea gets >= κ samples per pixel even where the tangent projection packs pixels
  // densest (gaze towards the edges).
  double fovea_disk_deg() const { return acuity::kFoveaDeg + params_.margin_deg + 1.0; }
  double fovea_pixel_density(glm::dvec3 g) const {
    glm::dvec3 b1, b2;
    orthonormal_basis(g, b1, b2);
    const double r = fovea_disk_deg() * kDeg;
    double best = view_.pixels_per_deg2(g);
    for (int k = 0; k < 64; ++k) {
      const double phi = 2 * kPi * k / 64;
      glm::dvec3 d = std::cos(r) * g + std::sin(r) * (std::cos(phi) * b1 + std::sin(phi) * b2);
      if (view_.clamp_to_frustum(d)) best = std::max(best, view_.pixels_per_deg2(d));
    }
    return best;
  }

  bool packing() const { return params_.pack && !params_.staircase; }

  // Whether one cap, κ·σ_disp over the whole view, falls short of the budget at a gaze on a
  // 9×9 lattice over the raster: σ_disp is lowest where the view's pixels are sparsest, which
  // on a wide, canted view is straight ahead, not its raster's centre. The view's solid angle
  // in deg² is summed over a 64×64 lattice of pixel blocks. Where one cap does pay the
  // budget (the headsets' presets at their default budget) the grid is what it always was.
  bool needs_ring_cap(double budget) const {
    constexpr int kBlocks = 64, kProbes = 9;
    double solid_deg2 = 0;
    const double bw = double(view_.width()) / kBlocks, bh = double(view_.height()) / kBlocks;
    for (int y = 0; y < kBlocks; ++y)
      for (int x = 0; x < kBlocks; ++x)
        solid_deg2 += bw * bh / view_.pixels_per_deg2(view_.pixel_to_dir({(x + 0.5) * bw, (y + 0.5) * bh}));
    for (int y = 0; y < kProbes; ++y)
      for (int x = 0; x < kProbes; ++x) {
        const double fx = x / (kProbes - 1.0), fy = y / (kProbes - 1.0);
        const glm::dvec3 g = view_.pixel_to_dir({fx * view_.width(), fy * view_.height()});
        if (params_.cap * fovea_pixel_density(g) * solid_deg2 < budget) return true;
      }
    return false;
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
    const double budget = budget_samples();
    ring_cap_ = needs_ring_cap(budget);
    const glm::dvec3 centre = gaze_ = view_.centre_dir();
    orthonormal_basis(centre, b1_, b2_);
    sides_ = frustum_sides(view_, centre, b1_, b2_);
    // Packed rings hold only their visible arc: the budget integrand carries the visible
    // fraction of the ring at each node (centred gaze).
    std::vector<double> visible;
    if (packing()) {
      visible.resize(size_t(kNodes) + 1);
      for (int k = 0; k <= kNodes; ++k) visible[size_t(k)] = 1 - visible_arc(view_sides(k * kStep)).second / (2 * kPi);
    }
    double dlog = 1;  // d log(samples) / d log σ0 at the budget's root
    auto solve_budget = [&](glm::dvec3 g, double& e_max) {
      set_density_cap(g);
      e_max = farthest_view_angle(g);
      double slope = 1;  // samples ∝ σ0 where σ is not capped
      return std::exp(solve_increasing(
          [&](double x, double& d) {
            build_prefix(std::exp(x), e_max, visible.empty() ? nullptr : &visible);
            const double total = std::max(prefix(e_max), 1e-300);
            d = dlog = prefix_dlog(std::exp(x), e_max) / total;
            return std::log(total / budget);
          },
          0.0, slope, 1e-12));
    };
    // The packed columns take their arcs at their inner radius and round their rows, an
    // outer column's ring is held out to its outer radius (part of it beyond the view's
    // edges: 7.6 % of the rows on `fove0`), and a mask hides some of what is left: a few
    // Newton steps on the samples the layout traces (on the view and not hidden, the
    // estimate fit_budget keeps at every gaze) bring those to the budget. The continuous
    // solve's slope starts them; then secants, since the traced samples grow more slowly in
    // σ0 than the held rows (the outer columns move out past the view's edges).
    auto fit_packed = [&](double s0, double e_max) {
      double x_prev = NAN, g_prev = NAN;
      for (int it = 0; it < 6 && packing(); ++it) {
        march(s0, e_max, 1 << 24, 0, &r_, &h_);
        full_.assign(h_.begin(), h_.end());
        const double traced = pack(1.0);
        const double x = std::log(s0), g = std::log(std::max(traced, 1.0) / budget);
        if (std::abs(g) < 1e-3) break;
        const double secant = (g - g_prev) / (x - x_prev);
        const double slope = std::isfinite(secant) && secant > 0.05 ? secant : std::max(dlog, 0.05);
        x_prev = x;
        g_prev = g;
        s0 = std::exp(x - g / slope);
      }
      return s0;
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
    double s0 = solve_budget(centre, e_centre);
    const double disp_centre = sigma_disp_;
    const std::vector<double> cap_centre = cap_;
    rows_ = int(std::min(std::ceil(rows_needed(s0, e_centre) - 1e-9), 1e8));
    // Off-centre gazes re-solve σ0 with the same N_ρ and may need more rows to keep the
    // anisotropy bound; more rows per column in turn mean fewer columns for the budget.
    const glm::dvec2 probes[] = {{0, 0}, {0.5, 0}, {1, 0}, {0, 0.5}, {1, 0.5}, {0, 1}, {0.5, 1}, {1, 1}};
    for (int round = 0; round < 2; ++round) {
      sigma_disp_ = disp_centre;
      cap_ = cap_centre;
      s0 = fit_packed(s0, e_centre);
      rows_ = std::max(rows_, int(std::min(std::ceil(rows_needed(s0, e_centre) - 1e-9), 1e8)));
      columns_ = std::max(1, int(std::ceil(march(s0, e_centre, 1 << 24) - 1e-9)));
      if (columns_ > (1 << 22) || rows_ > (1 << 22))
        throw InputError("visual-polar: grid of " + std::to_string(columns_) + "x" + std::to_string(rows_) +
                         " is too large for this display and budget");
      if (round == 1) break;
      for (const glm::dvec2 q : probes) {
        const glm::dvec3 g = view_.pixel_to_dir({q.x * view_.width(), q.y * view_.height()});
        set_density_cap(g);
        const double e_max = farthest_view_angle(g);
        const double x = solve_columns(e_max, std::log(s0));
        rows_ = std::max(rows_, int(std::ceil(rows_needed(std::exp(x), e_max) - 1e-9)));
      }
    }
    sigma_disp_ = disp_centre;
    cap_ = cap_centre;
    sigma0_ = s0;  // the first frame's warm start
  }

  std::vector<double> a_, circ_;        // per node: a(e), circ(e)
  std::vector<double> cap_;             // per node: κ·D(e) for the current gaze (set_density_cap)
  bool ring_cap_ = false;               // D(e) follows the rings' densest pixels (needs_ring_cap)
  mutable std::vector<double> f_, s_;   // per node for the current σ0: σ·circ and prefix
  glm::dvec3 b1_{1, 0, 0}, b2_{0, 1, 0};
  std::array<FrustumSide, 4> sides_{};  // the frustum seen from the gaze (per frame)
  double sigma0_ = 1, sigma_disp_ = 1, e_max_ = 0;
  double row_scale_ = 1;      // the budget's factor on σ0 for the rows (fit_budget)
  std::vector<double> column_acuity_;  // a(e) at each column's middle (this frame)
  // d log(columns)/d log σ0 for the warm start: ~1/2 (columns ∝ √σ0 where σ is not
  // capped), then the previous solve's first secant.
  double slope_ = 0.5;
  int evaluations_ = 0;       // column marches the last per-frame solve used
  struct {
    double sigma0, slope, e_max;
    std::vector<double> r;
  } session_;  // the warm-start state the session set-up leaves (forget_frames)
  bool reference_solve_ = false;
};

}  // namespace

std::optional<VisualPolarState> visual_polar_state(const SampleDistribution& d) {
  if (const auto* vp = dynamic_cast<const VisualPolar*>(&d)) return vp->state();
  return std::nullopt;
}

void set_reference_sigma0_solve(SampleDistribution& d, bool on) {
  auto* vp = dynamic_cast<VisualPolar*>(&d);
  if (!vp) throw std::invalid_argument("set_reference_sigma0_solve: not a visual-polar distribution");
  vp->set_reference_solve(on);
}

std::unique_ptr<SampleDistribution> make_visual_polar(const View& view, const DistributionParams& p,
                                                      const ViewMask* visibility) {
  return std::make_unique<VisualPolar>(view, p, visibility);
}

}  // namespace fovea::core
