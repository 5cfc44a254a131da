#pragma once
// Private: polar grids (angular Visual-Polar, paper-compatible VP, log-polar) share one
// representation — a column table of radius ranges [r_i, r_i+1) (linear within a column)
// and rows per column H_i over an arc of φ (φ = φ0_i + Δφ_i·v / H_i; a full ring, Δφ = 2π,
// unless the column is packed to its visible arc) — and differ only in what "radius" and
// "angle" mean: eccentricity on the sphere around the gaze, or pixels on the display.
#include <array>
#include <memory>
#include <utility>
#include <vector>

#include "fovea/core/distribution.hpp"

namespace fovea::core {

std::unique_ptr<SampleDistribution> make_visual_polar(const View& view, const DistributionParams& p,
                                                      const ViewMask* visibility);
std::unique_ptr<SampleDistribution> make_screen_polar(const View& view, const DistributionParams& p);

// One straight edge of the view seen from a polar grid's centre, for one ring: the ring's
// points with cos(φ − centre) > t lie beyond it (t >= 1: none; t <= −1: all).
struct HiddenSide {
  double t, centre;
};
using RingSides = std::array<HiddenSide, 4>;
// The ring's arc inside every edge as {φ0, gap}: [φ0, φ0 + 2π − gap), the circle minus its
// longest hidden run; {0, 0} for a ring no edge cuts and for a ring entirely hidden (not a
// ring of the view: kept full). The view is convex and holds the centre, so what is hidden
// at one radius stays hidden further out: a column's arc at its inner radius covers it.
std::pair<double, double> visible_arc(const RingSides& sides);
// The length of [φ0, φ0 + len) (len <= 2π) that the edges hide.
double hidden_within(const RingSides& sides, double phi0, double len);

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

  // The budget at every gaze. With full_ holding each column's full-ring rows, packs every
  // column to the arc of its ring the view's edges leave (at its inner radius) and scales
  // the rows (scaled_rows) by the c whose traced samples — on the view, not hidden,
  // estimated per column — equal those of the centred gaze (the first frame: its layout's,
  // or centre_reference); rows stay within the grid's. Returns c. Samples the view or the
  // lens would lose go back into the visible field in proportion to the density there.
  double fit_budget();
  // Packs with a given c (1: the full rings' spacing) and returns the traced estimate.
  double pack(double c);
  // The view's edges as seen by the ring at radius r.
  virtual RingSides view_sides(double r) const = 0;
  // The radius within which this frame's rings hold no pixel the mask hides.
  virtual double mask_free_radius() const = 0;
  // Column i's rows for a full ring when the samples are scaled by c: c·H_i by default.
  virtual double scaled_rows(int i, double c) const { return c * full_[size_t(i)]; }
  double traced_samples() const override { return traced_; }
  // The samples every frame traces, given those the layout traces at the centred gaze
  // with c = 1 (`own`): `own` unless the kind says otherwise.
  virtual double centre_reference(double own) const { return own; }

  std::vector<double> r_;  // columns_ + 1 radii
  std::vector<int> h_;     // columns_ rows, each in [1, rows_]
  // Per column the arc [φ0, φ0 + 2π − gap) its rows cover (radians); empty: full rings.
  std::vector<double> phi0_, gap_;
  std::vector<double> full_;  // per column the full ring's rows at c = 1 (set before fit_budget/pack)
  double traced_ = 0;         // the traced estimate of the current table
  // Per column the share of its scaled rows the grid's rows hold (1 unless capped).
  std::vector<double> rows_kept_;
  bool pack_arcs_ = true;     // false: every column a full ring

 private:
  // Per column, for the current r_ and gaze: the view arc at the inner radius and the
  // fraction of that arc's sector on the view (closed form) and not hidden (probed).
  void measure_columns();
  double traced_for(double c) const;
  double pack_measured(double c);
  std::vector<double> arc_phi0_, arc_gap_, usable_;
};

}  // namespace fovea::core
