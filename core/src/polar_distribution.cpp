#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <tuple>

#include "distribution_impl.hpp"
#include "fovea/core/eye_optics.hpp"

namespace fovea::core {

namespace {
constexpr double kTwoPi = 2 * std::numbers::pi;
// The share of a column's packed sector on the view and not hidden is measured along rings
// at kRadialProbes radii across the column, under a lens mask at kArcProbes points on each.
constexpr int kRadialProbes = 3, kArcProbes = 16;
// Range of the budget's scale on the rows, and bisection steps in log c (to ~1e-5).
constexpr double kScaleLo = 1.0 / 64, kScaleHi = 64;
constexpr int kScaleSteps = 40;
}  // namespace

namespace {

// The hidden runs of a ring, [start, end) with start in [0, 2π), disjoint on the circle and
// sorted; n = -1: the whole ring.
struct HiddenRuns {
  std::pair<double, double> run[4];
  int n = 0;
};

HiddenRuns hidden_runs(const RingSides& sides) {
  HiddenRuns h;
  std::pair<double, double> runs[4];
  int n = 0;
  for (const HiddenSide& side : sides) {
    if (!(side.t < 1)) continue;  // the ring lies inside this edge
    if (side.t <= -1) {           // wholly beyond it
      h.n = -1;
      return h;
    }
    const double half = std::acos(side.t);
    double start = std::fmod(side.centre - half, kTwoPi);
    if (start < 0) start += kTwoPi;
    runs[n++] = {start, start + 2 * half};
  }
  for (int k = 1; k < n; ++k)  // sort the (at most four) runs by start
    for (int j = k; j > 0 && runs[j].first < runs[j - 1].first; --j) std::swap(runs[j], runs[j - 1]);
  for (int k = 0; k < n; ++k) {  // merge on the line, then across 2π
    if (h.n > 0 && runs[k].first <= h.run[h.n - 1].second)
      h.run[h.n - 1].second = std::max(h.run[h.n - 1].second, runs[k].second);
    else
      h.run[h.n++] = runs[k];
  }
  while (h.n > 1 && h.run[h.n - 1].second >= h.run[0].first + kTwoPi) {  // the first run joins the last
    h.run[h.n - 1].second = std::max(h.run[h.n - 1].second, h.run[0].second + kTwoPi);
    std::copy(h.run + 1, h.run + h.n, h.run);
    --h.n;
  }
  if (h.n == 1 && h.run[0].second - h.run[0].first >= kTwoPi) h.n = -1;
  return h;
}

}  // namespace

std::pair<double, double> visible_arc(const RingSides& sides) {
  const HiddenRuns h = hidden_runs(sides);
  if (h.n <= 0) return {0.0, 0.0};
  int best = 0;
  for (int k = 1; k < h.n; ++k)
    if (h.run[k].second - h.run[k].first > h.run[best].second - h.run[best].first) best = k;
  return {std::fmod(h.run[best].second, kTwoPi), h.run[best].second - h.run[best].first};
}

double hidden_within(const RingSides& sides, double phi0, double len) {
  const HiddenRuns h = hidden_runs(sides);
  if (h.n < 0) return len;
  double a = std::fmod(phi0, kTwoPi), hidden = 0;
  if (a < 0) a += kTwoPi;
  for (int k = 0; k < h.n; ++k)
    for (double shift : {-kTwoPi, 0.0, kTwoPi})
      hidden += std::max(0.0, std::min(h.run[k].second + shift, a + len) - std::max(h.run[k].first + shift, a));
  return std::min(hidden, len);
}

double PolarDistribution::arc_fraction(int i) const { return gap_.empty() ? 1.0 : 1.0 - gap_[i] / kTwoPi; }

void PolarDistribution::map(glm::dvec2 grid, int column, glm::dvec3& dir, glm::dvec2& px) const {
  const double f = std::clamp(grid.x - column, 0.0, 1.0);
  const double r = r_[column] + f * (r_[column + 1] - r_[column]);
  const double phi0 = phi0_.empty() ? 0.0 : phi0_[column];
  from_polar(r, phi0 + kTwoPi * arc_fraction(column) * grid.y / h_[column], dir, px);
}

std::uint32_t PolarDistribution::cell_flags(int column, int row, glm::dvec3) const {
  return row >= h_[column] ? shaders::kCellClipped : 0u;
}

std::optional<glm::dvec2> PolarDistribution::screen_to_grid(glm::dvec2 px) const {
  double r, phi;
  if (!to_polar(px, r, phi)) return std::nullopt;
  // Column: the last boundary <= r (the table is increasing); radii beyond the table clamp
  // to its last column (as the resolve's clamp-to-edge on ρ).
  const auto it = std::upper_bound(r_.begin(), r_.end(), r);
  const int i = std::clamp(int(it - r_.begin()) - 1, 0, columns_ - 1);
  const double w = r_[i + 1] - r_[i];
  const double u = i + (w > 0 ? std::clamp((r - r_[i]) / w, 0.0, 1.0) : 0.5);
  // φ from the start of the column's arc, in turns; a point in a packed column's gap (off
  // the view, or within float rounding of its edge) snaps to the nearer end of the arc.
  double x = std::fmod((phi - (phi0_.empty() ? 0.0 : phi0_[i])) / kTwoPi, 1.0);
  if (x < 0) x += 1.0;
  const double span = arc_fraction(i);
  if (x > span) x = x - span < 1.0 - x ? span : 0.0;
  return glm::dvec2(u, x / span * h_[i]);
}

void PolarDistribution::measure_columns() {
  const size_t n = full_.size();
  arc_phi0_.assign(n, 0.0);
  arc_gap_.assign(n, 0.0);
  usable_.assign(n, 1.0);
  const double mask_free = mask_ ? mask_free_radius() : INFINITY;
  for (size_t i = 0; i < n; ++i) {
    if (pack_arcs_) std::tie(arc_phi0_[i], arc_gap_[i]) = visible_arc(view_sides(r_[i]));
    const double visible = kTwoPi - arc_gap_[i];
    double usable = 0;
    for (int a = 0; a < kRadialProbes; ++a) {
      const double r = r_[i] + (a + 0.5) / kRadialProbes * (r_[i + 1] - r_[i]);
      if (r_[i + 1] <= mask_free) {  // the edges alone: exact along each probed ring
        usable += 1 - hidden_within(view_sides(r), arc_phi0_[i], visible) / visible;
        continue;
      }
      int inside = 0;
      for (int b = 0; b < kArcProbes; ++b) {
        glm::dvec3 dir;
        glm::dvec2 px;
        from_polar(r, arc_phi0_[i] + (b + 0.5) / kArcProbes * visible, dir, px);
        inside += view_.contains_pixel(px) && mask_->visible_at(px);
      }
      usable += double(inside) / kArcProbes;
    }
    usable_[i] = usable / kRadialProbes;
  }
}

// Rows on the visible arc (a packed column's cells beyond it are off the view) times the
// usable share of that arc's sector.
double PolarDistribution::traced_for(double c) const {
  double sum = 0;
  for (size_t i = 0; i < full_.size(); ++i) {
    const double rows = scaled_rows(int(i), c);
    const double on_arc = arc_gap_[i] == 0 ? std::clamp(std::round(rows), 1.0, double(rows_))
                                           : std::clamp(rows * (1 - arc_gap_[i] / kTwoPi), 1.0, double(rows_));
    sum += usable_[i] * on_arc;
  }
  return sum;
}

double PolarDistribution::pack(double c) {
  measure_columns();
  return pack_measured(c);
}

double PolarDistribution::pack_measured(double c) {
  const size_t n = full_.size();
  h_.resize(n);
  rows_kept_.assign(n, 1.0);
  phi0_.clear();
  gap_.clear();
  if (pack_arcs_) {
    phi0_.assign(n, 0.0);
    gap_.assign(n, 0.0);
  }
  for (size_t i = 0; i < n; ++i) {
    const double rows = scaled_rows(int(i), c);
    const int ring = int(std::clamp(std::round(rows), 1.0, double(rows_)));
    h_[i] = ring;
    rows_kept_[i] = std::min(1.0, rows_ / std::max(rows, 1.0));
    if (arc_gap_[i] == 0) continue;
    // The visible arc at the full ring's spacing along φ (its rows · arc / 2π), widened to
    // whole rows around its centre, so σ and the anisotropy stay the ring's even for arcs of
    // a few rows. Arcs are rounded to float, the GPU table's precision, so CPU and GPU map
    // cells identically.
    const double visible = kTwoPi - arc_gap_[i];
    const double want = rows * visible / kTwoPi;
    rows_kept_[i] = std::min(1.0, rows_ / std::max(want, 1.0));
    // Beyond the grid's rows: its rows spread over the arc, half a row past each end so a
    // pixel on the arc's edge lands inside, as it does in a widened arc.
    const bool capped = want > rows_ - 1;
    const int packed = capped ? rows_ : int(std::clamp(std::ceil(want - 1e-9), 1.0, double(rows_)));
    const double arc = capped ? visible * rows_ / std::max(rows_ - 1, 1) : kTwoPi * packed / rows;
    if (arc >= kTwoPi || (!capped && packed >= ring)) continue;  // a complete ring: stays full and wraps
    h_[i] = packed;
    phi0_[i] = float(arc_phi0_[i] - 0.5 * (arc - visible));
    gap_[i] = float(kTwoPi - arc);
  }
  traced_ = traced_for(c);
  return traced_;
}

double PolarDistribution::fit_budget() {
  measure_columns();
  bool reference = false;
  if (!(centre_traced_ > 0)) {  // the centred gaze the session starts with: the reference
    // A layout within 2 % of its reference is its own: c = 1, the cells as laid out (its
    // whole columns and rounded rows: `tiny`'s 32 columns trace 1.016 of its budget).
    const double own = traced_for(1.0);
    centre_traced_ = centre_reference(own);
    if (std::abs(centre_traced_ - own) <= 0.02 * centre_traced_) {
      centre_traced_ = own;
      pack_measured(1.0);
      return 1.0;
    }
    reference = true;
  }
  const double target = budget_samples();
  double lo = std::log(kScaleLo), hi = std::log(kScaleHi);
  for (int it = 0; it < kScaleSteps; ++it) {
    const double mid = 0.5 * (lo + hi);
    (traced_for(std::exp(mid)) < target ? lo : hi) = mid;
  }
  const double c = std::exp(hi);
  // A reference the grid cannot come down or up to (rows at their bounds, beyond the
  // bisection's rounding) is what it reaches: every gaze then keeps that.
  if (reference) {
    const double reached = traced_for(c);
    if (std::abs(reached - centre_traced_) > 0.01 * centre_traced_) centre_traced_ = reached;
  }
  pack_measured(c);
  return c;
}

void PolarDistribution::publish_table() {
  table_.resize(size_t(columns_));
  for (int i = 0; i < columns_; ++i)
    table_[i] = {float(r_[i]), float(r_[i + 1]), std::uint32_t(h_[i]), phi0_.empty() ? 0.0f : float(phi0_[i]),
                 gap_.empty() ? 0.0f : float(gap_[i]), 0.0f, 0.0f, 0.0f};
}

void PolarDistribution::fill_gpu(shaders::GridParams& g) const { g.kill = 0; }

}  // namespace fovea::core
