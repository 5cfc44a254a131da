#include <algorithm>
#include <cmath>
#include <numbers>

#include "distribution_impl.hpp"

namespace fovea::core {

namespace {
constexpr double kTwoPi = 2 * std::numbers::pi;
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

void PolarDistribution::publish_table() {
  table_.resize(size_t(columns_));
  for (int i = 0; i < columns_; ++i)
    table_[i] = {float(r_[i]), float(r_[i + 1]), std::uint32_t(h_[i]), phi0_.empty() ? 0.0f : float(phi0_[i]),
                 gap_.empty() ? 0.0f : float(gap_[i]), 0.0f, 0.0f, 0.0f};
}

void PolarDistribution::fill_gpu(shaders::GridParams& g) const { g.kill = 0; }

}  // namespace fovea::core
