#pragma once
// Private: polar grids (angular Visual-Polar, paper-compatible VP, log-polar) share one
// representation — a column table of radius ranges [r_i, r_i+1) (linear within a column)
// and rows per column H_i over an arc of φ (φ = φ0_i + Δφ_i·v / H_i; a full ring, Δφ = 2π,
// unless the column is packed to its visible arc) — and differ only in what "radius" and
// "angle" mean: eccentricity on the sphere around the gaze, or pixels on the display.
#include <memory>
#include <vector>

#include "fovea/core/distribution.hpp"

namespace fovea::core {

std::unique_ptr<SampleDistribution> make_visual_polar(const View& view, const DistributionParams& p);
std::unique_ptr<SampleDistribution> make_screen_polar(const View& view, const DistributionParams& p);

class PolarDistribution : public SampleDistribution {
 public:
  std::optional<glm::dvec2> screen_to_grid(glm::dvec2 px) const override;
  // Current column table: boundaries (columns + 1) and rows per column.
  const std::vector<double>& radii() const { return r_; }
  const std::vector<int>& rows_per_column() const { return h_; }

 protected:
  using SampleDistribution::SampleDistribution;
  // (radius, φ) <-> direction and display position.
  virtual void from_polar(double r, double phi, glm::dvec3& dir, glm::dvec2& px) const = 0;
  virtual bool to_polar(glm::dvec2 px, double& r, double& phi) const = 0;

  void map(glm::dvec2 grid, int column, glm::dvec3& dir, glm::dvec2& px) const override;
  std::uint32_t cell_flags(int column, int row, glm::dvec3 dir) const override;
  void fill_gpu(shaders::GridParams& g) const override;
  // Copies r_/h_ (and the arcs) into the GPU table; call at the end of on_frame().
  void publish_table();
  // Fraction of the full circle column i's rows cover (1 for a full ring).
  double arc_fraction(int i) const;

  std::vector<double> r_;  // columns_ + 1 radii
  std::vector<int> h_;     // columns_ rows, each in [1, rows_]
  // Per column the arc [φ0, φ0 + 2π − gap) its rows cover (radians); empty: full rings.
  std::vector<double> phi0_, gap_;
};

}  // namespace fovea::core
