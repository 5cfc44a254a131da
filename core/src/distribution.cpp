// Common parts of the sample distributions and the raster-based ones (Cartesian full,
// Cartesian uniform at equal budget, Weier's linear fall-off).
#include "fovea/core/distribution.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "distribution_impl.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/shaders/hash.h"

namespace fovea::core {

namespace {
struct Name {
  DistributionKind kind;
  const char* name;
};
constexpr Name kNames[] = {{DistributionKind::VisualPolar, "visual-polar"},
                           {DistributionKind::PaperVisualPolar, "paper-visual-polar"},
                           {DistributionKind::Cartesian, "cartesian"},
                           {DistributionKind::CartesianUniform, "cartesian-uniform"},
                           {DistributionKind::LinearFalloff, "linear-falloff"},
                           {DistributionKind::LogPolar, "log-polar"}};
}  // namespace

DistributionKind parse_distribution(std::string_view s) {
  std::string all;
  for (const auto& n : kNames) {
    if (s == n.name) return n.kind;
    all += std::string(all.empty() ? "" : "|") + n.name;
  }
  throw InputError("distribution: unknown \"" + std::string(s) + "\" (expected " + all + ")");
}

bool parse_jitter(std::string_view s) {
  if (s == "on") return true;
  if (s == "off") return false;
  throw InputError("--jitter: unknown \"" + std::string(s) + "\" (expected on|off)");
}

const char* distribution_name(DistributionKind k) {
  for (const auto& n : kNames)
    if (n.kind == k) return n.name;
  return "?";
}

void DistributionParams::validate() const {
  auto need = [](bool ok, const std::string& what) {
    if (!ok) throw InputError(what);
  };
  need(std::isfinite(budget) && budget >= 0.01 && budget <= 1.0, "budget: must be in [0.01, 1] (fraction of display pixels)");
  need(std::isfinite(margin_deg) && margin_deg >= 0 && margin_deg <= 30, "margin: must be in [0, 30] degrees");
  need(gamma == 1.0 || gamma == 2.0, "gamma: must be 1 or 2");
  need(std::isfinite(cap) && cap > 0 && cap <= 16, "cap: must be in (0, 16] samples per display pixel");
  need(std::isfinite(aniso) && aniso >= 1 && aniso <= 64, "aniso: must be in [1, 64]");
  need(std::isfinite(falloff_fovea_deg) && std::isfinite(falloff_periphery_deg) && falloff_fovea_deg >= 0 &&
           falloff_periphery_deg > falloff_fovea_deg,
       "linear fall-off: need 0 <= fl < pl");
  need(std::isfinite(falloff_min_p) && falloff_min_p > 0 && falloff_min_p <= 1, "linear fall-off: Pp must be in (0, 1]");
  need(std::isfinite(logpolar_alpha) && logpolar_alpha >= 1 && logpolar_alpha <= 8, "log-polar: alpha must be in [1, 8]");
}

void orthonormal_basis(glm::dvec3 n, glm::dvec3& b1, glm::dvec3& b2) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double b = n.x * n.y * a;
  b1 = {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x};
  b2 = {b, sign + n.y * n.y * a, -n.y};
}

double halton(std::uint32_t i, std::uint32_t base) {
  double f = 1, r = 0;
  while (i > 0) {
    f /= base;
    r += f * (i % base);
    i /= base;
  }
  return r;
}

GazeStatus SampleDistribution::set_frame(glm::dvec3 g, std::uint32_t frame) {
  GazeStatus st;
  const double len = glm::length(g);
  glm::dvec3 d = (std::isfinite(len) && len > 1e-12) ? g / len : glm::dvec3(0);
  const bool usable = d != glm::dvec3(0) && d.z < 0;
  if (usable) {
    const glm::dvec3 before = d;
    view_.clamp_to_frustum(d);
    st.clamped = glm::length(d - before) > 1e-12;
    last_valid_gaze_ = d;
    has_valid_gaze_ = true;
  } else {
    st.fallback = true;
    d = has_valid_gaze_ ? last_valid_gaze_ : view_.centre_dir();
  }
  gaze_ = d;
  st.used = d;
  frame_ = frame;
  on_frame();
  return st;
}

glm::dvec2 SampleDistribution::jitter() const {
  if (!jitter_) return {0, 0};
  // Halton (2, 3) over frames, the usual TAA sequence; index 0 is skipped (it is 0, 0).
  const std::uint32_t i = (frame_ % 1024u) + 1u;
  return {halton(i, 2) - 0.5, halton(i, 3) - 0.5};
}

shaders::GridSample SampleDistribution::sample_at(int column, int row, glm::dvec2 j) const {
  shaders::GridSample s{};
  if (column >= columns_ || row >= rows_) {
    s.flags = shaders::kCellPadding;
    s.dir_z = -1;
    return s;
  }
  glm::dvec3 dir;
  glm::dvec2 px;
  map({column + 0.5 + j.x, row + 0.5 + j.y}, column, dir, px);
  std::uint32_t flags = cell_flags(column, row, dir);
  // On the display and not hidden is the cell centre's, whatever the jitter: a cell at an
  // edge that came and went with the jitter lost its history every time it went.
  glm::dvec2 centre = px;
  if (j != glm::dvec2(0)) {
    glm::dvec3 centre_dir;
    map({column + 0.5, row + 0.5}, column, centre_dir, centre);
  }
  if (!view_.contains_pixel(centre, shaders::kCellEdgeTolPx)) flags |= shaders::kCellOffscreen;
  // Only cells that would be traced are tested against the mask (as the GPU does): a
  // packed column's clipped rows map beyond its arc, often into the hidden area.
  else if (flags == 0 && mask_ && !mask_->visible_at(centre)) flags |= shaders::kCellHidden;
  s.dir_x = float(dir.x);
  s.dir_y = float(dir.y);
  s.dir_z = float(dir.z);
  s.flags = flags;
  // Positions far outside the display are irrelevant (the cell is skipped); keep them finite.
  s.screen_x = float(std::clamp(px.x, -1e6, 1e6));
  s.screen_y = float(std::clamp(px.y, -1e6, 1e6));
  s.ecc_deg = float(angle_deg(dir, gaze_));
  const double ppc = pixels_per_cell(column, dir);
  s.footprint = float(std::isfinite(ppc) ? std::clamp(std::sqrt(std::max(ppc, 0.0)), 1e-6, 1e6) : 1e6);
  return s;
}

std::uint32_t SampleDistribution::cell_flags(int, int, glm::dvec3) const { return 0; }

void SampleDistribution::adopt_mask(const ViewMask& mask) {
  if (mask.width() != view_.width() || mask.height() != view_.height())
    throw InputError("visibility mask: " + std::to_string(mask.width()) + "x" + std::to_string(mask.height()) +
                     " differs from the view's raster " + std::to_string(view_.width()) + "x" +
                     std::to_string(view_.height()));
  mask_ = std::make_shared<const ViewMask>(mask);
  visible_fraction_ = 1.0 - mask.hidden_fraction();
  const glm::dvec3 centre = view_.centre_dir();
  const glm::dvec2 centre_px =
      view_.dir_to_pixel(centre).value_or(glm::dvec2(0.5 * view_.width(), 0.5 * view_.height()));
  mask_free_deg_ = mask_free_px_ = INFINITY;
  for (int y = 0; y < mask.height(); ++y)
    for (int x = 0; x < mask.width(); ++x) {
      if (!mask.hidden(x, y)) continue;
      // The pixel's nearest point to the centre, so the disk holds no part of it.
      const glm::dvec2 near{std::clamp(centre_px.x, double(x), x + 1.0), std::clamp(centre_px.y, double(y), y + 1.0)};
      mask_free_px_ = std::min(mask_free_px_, glm::length(near - centre_px));
      mask_free_deg_ = std::min(mask_free_deg_, angle_deg(view_.pixel_to_dir(near), centre));
    }
  // Two pixels of margin for the pixel-to-angle rounding above.
  mask_free_px_ -= 2;
  mask_free_deg_ -= 2 / std::sqrt(view_.pixels_per_deg2(centre));
}

void SampleDistribution::set_visibility(const ViewMask& mask) {
  adopt_mask(mask);
  const glm::dvec3 centre = view_.centre_dir();
  if (centre_traced_ > 0) {  // the polar kinds' reference: the centred gaze under the mask
    const glm::dvec3 gaze = gaze_;
    centre_traced_ = 0;
    gaze_ = centre;
    on_frame();
    gaze_ = gaze;
  }
  on_frame();
}

double SampleDistribution::budget_samples() const {
  if (centre_traced_ > 0) return centre_traced_;
  return std::max(1.0, params_.budget * view_.width() * view_.height() * visible_fraction_);
}

double SampleDistribution::traced_samples() const { return grid_samples() * visible_fraction_; }

double SampleDistribution::samples_per_pixel(glm::dvec2 px) const {
  // One sample per cell: the inverse of the cell's area on the display where px falls.
  const auto g = screen_to_grid(px);
  if (!g) return 0;
  const int column = std::clamp(int(g->x), 0, columns_ - 1);
  const double ppc = pixels_per_cell(column, view_.pixel_to_dir(px));
  return ppc > 0 && std::isfinite(ppc) ? 1.0 / ppc : 0;
}

double SampleDistribution::grid_samples() const {
  if (table_.empty()) return double(columns_) * rows_;
  double n = 0;
  for (const auto& c : table_) n += c.rows;
  return n;
}

shaders::GridParams SampleDistribution::gpu_params() const {
  shaders::GridParams g{};
  g.columns = std::uint32_t(columns_);
  g.rows = std::uint32_t(rows_);
  g.padded_columns = std::uint32_t(padded_columns());
  g.padded_rows = std::uint32_t(padded_rows());
  g.frame = frame_;
  g.seed = params_.seed;
  g.gaze_x = float(gaze_.x);
  g.gaze_y = float(gaze_.y);
  g.gaze_z = float(gaze_.z);
  glm::dvec3 b1, b2;
  orthonormal_basis(gaze_, b1, b2);
  g.b1_x = float(b1.x), g.b1_y = float(b1.y), g.b1_z = float(b1.z);
  g.b2_x = float(b2.x), g.b2_y = float(b2.y), g.b2_z = float(b2.z);
  g.width = float(view_.width());
  g.height = float(view_.height());
  g.tan_left = float(view_.tan_left());
  g.tan_right = float(view_.tan_right());
  g.tan_up = float(view_.tan_up());
  g.tan_down = float(view_.tan_down());
  const glm::dvec2 gp = view_.dir_to_pixel(gaze_).value_or(glm::dvec2(0));
  g.gaze_px_x = float(gp.x);
  g.gaze_px_y = float(gp.y);
  const glm::dvec2 j = jitter();
  g.jitter_u = float(j.x);
  g.jitter_v = float(j.y);
  fill_gpu(g);
  return g;
}

// ---- Cartesian raster family --------------------------------------------------------

namespace {

class RasterDistribution final : public SampleDistribution {
 public:
  RasterDistribution(const View& v, const DistributionParams& p) : SampleDistribution(v, p) {
    if (p.kind == DistributionKind::CartesianUniform) {
      const double k = std::sqrt(p.budget);
      columns_ = std::max(1, int(std::lround(v.width() * k)));
      rows_ = std::max(1, int(std::lround(v.height() * k)));
    } else {
      columns_ = v.width();
      rows_ = v.height();
    }
    set_frame(v.centre_dir());
  }

  // Linear fall-off keeps the raster: killed cells are holes the reconstruction fills.
  std::optional<glm::dvec2> screen_to_grid(glm::dvec2 px) const override {
    if (!std::isfinite(px.x) || !std::isfinite(px.y)) return std::nullopt;
    return glm::dvec2(px.x * columns_ / view_.width(), px.y * rows_ / view_.height());
  }

  // Dissertation Eq. 4.1: 1 inside fl, linear to Pp at pl, Pp beyond; fl and pl are the
  // parameters' scaled by this frame's budget factor.
  double keep_probability(double e, double scale) const {
    const auto& p = params_;
    const double fl = scale * p.falloff_fovea_deg, pl = scale * p.falloff_periphery_deg;
    if (e <= fl) return 1.0;
    if (e >= pl) return p.falloff_min_p;
    return 1.0 + (e - fl) * (p.falloff_min_p - 1.0) / (pl - fl);
  }
  double keep_probability(double e) const { return keep_probability(e, scale_); }

  double grid_samples() const override {
    return params_.kind == DistributionKind::LinearFalloff ? expected_kept_ : SampleDistribution::grid_samples();
  }
  double traced_samples() const override {
    return params_.kind == DistributionKind::LinearFalloff ? expected_traced_ : SampleDistribution::traced_samples();
  }

  double target_density(glm::dvec3 dir) const override {
    const double per_pixel = double(columns_) * rows_ / (double(view_.width()) * view_.height());
    const double k = params_.kind == DistributionKind::LinearFalloff ? keep_probability(angle_deg(dir, gaze_)) : 1.0;
    return k * per_pixel * view_.pixels_per_deg2(dir);
  }

  double pixels_per_cell(int, glm::dvec3) const override {
    return double(view_.width()) * view_.height() / (double(columns_) * rows_);
  }

  double samples_per_pixel(glm::dvec2 px) const override {
    if (params_.kind == DistributionKind::LinearFalloff)
      return keep_probability(angle_deg(view_.pixel_to_dir(px), gaze_));
    return double(columns_) * rows_ / (double(view_.width()) * view_.height());
  }

 protected:
  void map(glm::dvec2 grid, int, glm::dvec3& dir, glm::dvec2& px) const override {
    px = {grid.x * view_.width() / columns_, grid.y * view_.height() / rows_};
    dir = view_.pixel_to_dir(px);
  }
  // Linear fall-off: the factor on (fl, pl) whose expected kept pixels are the budget, by
  // bisection over the eccentricities of a subsampled raster (the mean keep probability
  // grows with the factor, from Pp at 0 to 1 once fl passes the farthest pixel). Pixels the
  // lens hides are never traced: the mean is over the visible ones.
  void on_frame() override {
    if (params_.kind != DistributionKind::LinearFalloff) return;
    const int step = std::max(1, int(std::sqrt(double(view_.width()) * view_.height() / 40000.0)));
    std::vector<double> ecc, hidden;
    for (int y = step / 2; y < view_.height(); y += step)
      for (int x = step / 2; x < view_.width(); x += step) {
        const glm::dvec2 px{x + 0.5, y + 0.5};
        (mask_ && !mask_->visible_at(px) ? hidden : ecc).push_back(angle_deg(view_.pixel_to_dir(px), gaze_));
      }
    if (ecc.empty()) ecc.swap(hidden);  // everything hidden: keep the budget's shape
    const auto mean_keep = [&](const std::vector<double>& es, double scale) {
      double sum = 0;
      for (double e : es) sum += keep_probability(e, scale);
      return es.empty() ? 0.0 : sum / double(es.size());
    };
    const double e_max = *std::max_element(ecc.begin(), ecc.end());
    double lo = 0, hi = std::max(1.0, e_max / std::max(params_.falloff_fovea_deg, 1e-3) + 1);
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (mean_keep(ecc, mid) < params_.budget ? lo : hi) = mid;
    }
    scale_ = 0.5 * (lo + hi);
    const double pixels = double(view_.width()) * view_.height(), n = double(ecc.size() + hidden.size());
    expected_traced_ = mean_keep(ecc, scale_) * pixels * visible_fraction_;
    expected_kept_ = expected_traced_ + mean_keep(hidden, scale_) * pixels * double(hidden.size()) / n;
  }
  std::uint32_t cell_flags(int column, int row, glm::dvec3 dir) const override {
    if (params_.kind != DistributionKind::LinearFalloff) return 0;
    const double u = shaders::hash_to_unit(shaders::hash3(std::uint32_t(column), std::uint32_t(row),
                                                          frame_ * 0x9E3779B9u + params_.seed));
    return u < keep_probability(angle_deg(dir, gaze_)) ? 0 : shaders::kCellKilled;
  }
  void fill_gpu(shaders::GridParams& g) const override {
    g.family = shaders::kFamilyCartesian;
    g.kill = params_.kind == DistributionKind::LinearFalloff ? 1u : 0u;
    g.fl_deg = float(scale_ * params_.falloff_fovea_deg);
    g.pl_deg = float(scale_ * params_.falloff_periphery_deg);
    g.pp = float(params_.falloff_min_p);
  }

 private:
  double scale_ = 1, expected_kept_ = 0, expected_traced_ = 0;
};

// Visual-Polar lays its grid out for the pixels `visibility` leaves; the other kinds' layouts
// do not depend on it (make_distribution sets it once their budget is checked).
std::unique_ptr<SampleDistribution> make_unchecked(const View& view, const DistributionParams& p,
                                                   const ViewMask* visibility) {
  switch (p.kind) {
    case DistributionKind::VisualPolar: return make_visual_polar(view, p, visibility);
    case DistributionKind::PaperVisualPolar:
    case DistributionKind::LogPolar: return make_screen_polar(view, p);
    default: return std::make_unique<RasterDistribution>(view, p);
  }
}

std::string fraction(double f) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", f);
  return buf;
}

// The distribution, its budget met at the centred gaze it starts with or refused.
// `layout_mask`: its grid laid out for the pixels `visibility` leaves (Visual-Polar); else
// the mask, where given, is set after the check.
std::unique_ptr<SampleDistribution> checked(const View& view, const DistributionParams& p, const ViewMask* visibility,
                                            bool layout_mask) {
  const ViewMask* layout = layout_mask ? visibility : nullptr;
  auto d = make_unchecked(view, p, layout);
  const auto masked = [&] {
    if (visibility && !layout_mask) d->set_visibility(*visibility);
    return std::move(d);
  };
  // Cartesian: every pixel, whatever the budget. P5's staircase rounds rows up per 32
  // columns on top of the budgeted grid (+12% on `small`): an option of the layout study.
  if (p.kind == DistributionKind::Cartesian || p.staircase) return masked();
  // Two samples of slack let displays of a few pixels keep their minimal grids.
  const double pixels = double(view.width()) * view.height();
  const double got = d->budgeted_samples() / pixels;
  if (std::abs(got - p.budget) * pixels <= std::max(0.05 * p.budget * pixels, 2.0)) return masked();
  const std::string name = (p.display.empty() ? "" : "display " + p.display + ": ") + "budget: " + distribution_name(p.kind);
  const std::string where = " on this " + std::to_string(view.width()) + "x" + std::to_string(view.height()) + " display";
  if (got < p.budget) {
    DistributionParams full = p;
    full.budget = 1.0;
    const double most = make_unchecked(view, full, layout)->budgeted_samples() / pixels;
    throw InputError(name + " reaches at most " + fraction(std::max(most, got)) + " of the display's pixels" +
                     where + " (requested " + fraction(p.budget) + ")");
  }
  throw InputError(name + " reaches no less than " + fraction(got) + " of the display's pixels" + where +
                   " (requested " + fraction(p.budget) + ")");
}

}  // namespace

std::unique_ptr<SampleDistribution> make_distribution(const View& view, const DistributionParams& p,
                                                      const ViewMask* visibility) {
  p.validate();
  // Visual-Polar lays its grid out for the pixels a mask leaves. Where that layout cannot
  // meet the budget (a mask that leaves no pixel, or fewer than the least grid traces), the
  // grid is laid out for the whole view and the mask set after it, as a mask set later is:
  // it traces what the mask leaves.
  if (visibility && p.kind == DistributionKind::VisualPolar) {
    try {
      return checked(view, p, visibility, true);
    } catch (const InputError&) {
    }
  }
  return checked(view, p, visibility, false);
}

}  // namespace fovea::core
