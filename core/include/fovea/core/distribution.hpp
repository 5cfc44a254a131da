#pragma once
// Sample distributions behind one interface: where each cell of a 2-D sample grid looks
// (view direction, display position), and — where the mapping is invertible — which grid
// coordinate a display position falls on. The path tracer traces one ray per cell; the
// reconstruction works on the grid; the resolve maps back to the display.
//
//   visual-polar        angular Visual-Polar (docs/visual-polar.md): density σ(e) =
//                       min(κσ_disp, σ0·a(e)) around the gaze on the sphere of directions
//   paper-visual-polar  P5 as published: screen-plane polar grid, P4 Eq. 7 polynomial,
//                       linear fovea with a fixed 12% triangle clip
//   cartesian           one cell per display pixel (the reference sampling)
//   cartesian-uniform   a uniformly scaled raster with the same budget
//   linear-falloff      Weier et al. 2016: full raster, pixels kept with probability p(e)
//   log-polar           Meng et al. 2018 kernel log-polar buffer (σ = 1.8, α = 4)
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "fovea/core/view.hpp"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/grid_params.h"

namespace fovea::core {

enum class DistributionKind { VisualPolar, PaperVisualPolar, Cartesian, CartesianUniform, LinearFalloff, LogPolar };

DistributionKind parse_distribution(std::string_view name);  // InputError on unknown names
bool parse_jitter(std::string_view s);                       // --jitter: "on" | "off", else InputError
const char* distribution_name(DistributionKind k);

struct DistributionParams {
  DistributionKind kind = DistributionKind::VisualPolar;
  // Grid samples as a fraction of display pixels: met within ±5% at a centred gaze by every
  // kind but cartesian (always 1), or make_distribution refuses it naming what is reachable.
  double budget = 0.39;
  double margin_deg = 1.0;   // s: fovea margin for tracker error
  double gamma = 1.0;        // a(e) = m(max(e − s, 0))^γ; 1 (papers) or 2 (2-D Nyquist)
  double cap = 1.0;          // κ: at most this many samples per display pixel
  double aniso = 2.0;        // A: bound on φ-spacing / ρ-spacing
  bool staircase = false;    // P5's rows-constant-per-32-columns layout (VP option)
  bool pack = true;          // polar kinds: each ring's rows only on its visible arc (VP: not with staircase)
  // Weier 2016; fl and pl are scaled together per frame so the kept pixels meet the budget.
  double falloff_fovea_deg = 10, falloff_periphery_deg = 20, falloff_min_p = 0.2;
  double logpolar_alpha = 4.0;  // Meng 2018; the buffer's σ is 1/√budget
  std::uint32_t seed = 0;    // random killing (linear fall-off)
  bool jitter = true;        // per-frame Halton (2, 3) sub-cell offset (anti-aliasing over frames)
  // The display the view comes from (DisplayPreset::origin: preset name or file), named in
  // make_distribution's budget refusals; a budget a wide-FOV file cannot meet is its problem.
  std::string display;

  void validate() const;     // InputError naming the parameter
};

// What set_frame did with the requested gaze.
struct GazeStatus {
  glm::dvec3 used{0, 0, -1};
  bool clamped = false;   // was outside the frustum, clamped to its border
  bool fallback = false;  // unusable (NaN, zero, backwards): last valid gaze or view centre used
};

class ViewMask;

class SampleDistribution {
 public:
  virtual ~SampleDistribution() = default;

  DistributionKind kind() const { return params_.kind; }
  const DistributionParams& params() const { return params_; }
  const View& view() const { return view_; }

  // The logical grid (fixed for the session) and its allocation padded to 32×32 blocks.
  int columns() const { return columns_; }
  int rows() const { return rows_; }
  int padded_columns() const { return (columns_ + 31) / 32 * 32; }
  int padded_rows() const { return (rows_ + 31) / 32 * 32; }

  // Per frame: the gaze (unit view-space direction, OpenXR convention) and the frame
  // index (drives sub-cell jitter when enabled and the random killing).
  GazeStatus set_frame(glm::dvec3 gaze, std::uint32_t frame = 0);
  // Back to the state right after construction (gaze at the view centre, no state carried
  // from earlier frames such as the σ0 solve's warm start), so a new sequence maps exactly
  // as in a fresh distribution.
  void restart() {
    forget_frames();
    set_frame(view_.centre_dir());
  }
  glm::dvec3 gaze() const { return gaze_; }
  void set_jitter(bool on) { jitter_ = on; }
  glm::dvec2 jitter() const;  // this frame's cell offset in [-0.5, 0.5)²

  // The view pixels the lens hides (optional): cells there are flagged hidden, and the
  // budget counts only the pixels it leaves visible. Rebuilds the current frame. A mask
  // known before the distribution is made goes to make_distribution instead: Visual-Polar
  // then lays its session grid out for the pixels the mask leaves (set later, the rows of
  // its periphery take up the difference).
  void set_visibility(const ViewMask& mask);

  // The sample of cell (column, row), 0 <= column < padded_columns, 0 <= row < padded_rows.
  shaders::GridSample sample(int column, int row) const { return sample_at(column, row, jitter()); }
  // The same with an explicit offset from the cell centre, in cells ([-0.5, 0.5)²).
  shaders::GridSample sample_at(int column, int row, glm::dvec2 offset) const;
  // Continuous grid coordinates (column, row), cell centres at +0.5, of a display
  // position, for invertible distributions; nullopt otherwise.
  virtual std::optional<glm::dvec2> screen_to_grid(glm::dvec2 px) const = 0;
  virtual bool invertible() const { return true; }
  // Intended samples per square degree at a view direction.
  virtual double target_density(glm::dvec3 dir) const = 0;
  // Expected samples per display pixel around a display position (the inverse area of
  // the cell covering it; the keep probability for linear fall-off).
  virtual double samples_per_pixel(glm::dvec2 px) const;
  // Samples of the current frame's grid: cells neither clipped, padding nor killed
  // (linear fall-off: the expected count); offscreen and hidden cells included.
  virtual double grid_samples() const;
  // The samples the budget sets, which make_distribution checks at the centred gaze: the
  // grid samples; the screen-polar kinds' published grid (packed, its rows are rescaled);
  // Visual-Polar's traced on the view over the share a mask leaves (its outer columns' rings
  // reach past the view's edges).
  virtual double budgeted_samples() const { return grid_samples(); }
  // The samples this frame traces: grid samples on the view and not hidden (estimated per
  // column for polar grids, expected for linear fall-off). Every kind but cartesian keeps
  // it at budget_samples() at any gaze, as far as its grid allows.
  virtual double traced_samples() const;
  // The samples every frame traces: raster kinds and Visual-Polar the budget fraction of the
  // view pixels the mask leaves visible (Visual-Polar: as far as its rows can come down or up,
  // or its layout's own count within 2 % of that); the screen-polar kinds what their grid
  // traces at the centred gaze (P5's and Meng's layouts as published: some of it beyond the
  // view's edges).
  double budget_samples() const;

  // GPU description of the current frame (uniforms + column table; see grid_params.h).
  shaders::GridParams gpu_params() const;
  const std::vector<shaders::GridColumn>& column_table() const { return table_; }

 protected:
  SampleDistribution(const View& view, const DistributionParams& p) : view_(view), params_(p), jitter_(p.jitter) {}
  // Continuous grid position (cell centre + jitter) -> unit direction and display position.
  virtual void map(glm::dvec2 grid, int column, glm::dvec3& dir, glm::dvec2& px) const = 0;
  virtual void on_frame() = 0;                    // rebuild per-frame state after the gaze moved
  virtual void forget_frames() {}                 // drop state carried between frames (restart)
  virtual std::uint32_t cell_flags(int column, int row, glm::dvec3 dir) const;  // clip/kill
  virtual void fill_gpu(shaders::GridParams& g) const = 0;
  // Display pixels covered by one cell of `column` around direction `dir`.
  virtual double pixels_per_cell(int column, glm::dvec3 dir) const = 0;
  // set_visibility's bookkeeping without the rebuild (a constructor's, before its layout).
  void adopt_mask(const ViewMask& mask);

  View view_;
  DistributionParams params_;
  int columns_ = 1, rows_ = 1;
  glm::dvec3 gaze_{0, 0, -1};
  glm::dvec3 last_valid_gaze_{0, 0, -1};
  bool has_valid_gaze_ = false;
  std::uint32_t frame_ = 0;
  bool jitter_ = true;
  std::shared_ptr<const ViewMask> mask_;
  double visible_fraction_ = 1;  // of the view's pixels, by the mask
  // The largest disk around the view centre the mask hides nothing of: its radius in
  // degrees (around the centre direction) and in pixels (around the centre pixel).
  double mask_free_deg_ = INFINITY, mask_free_px_ = INFINITY;
  double centre_traced_ = 0;  // polar kinds: traced at the centred gaze (0: not yet known)
  std::vector<shaders::GridColumn> table_;  // polar kinds: per column radius range and rows
};

// `visibility` (optional): the lens' mask of the view, as set_visibility.
std::unique_ptr<SampleDistribution> make_distribution(const View& view, const DistributionParams& p,
                                                      const ViewMask* visibility = nullptr);

// The angular Visual-Polar construction's per-frame state (nullopt for other kinds).
struct VisualPolarState {
  double sigma0 = 0;       // acuity scale solved for this frame's columns (samples/deg² at m = 1)
  // The factor on σ0 the rows take so the traced samples meet the budget (the columns stay
  // σ0's; 1 at a centred gaze, more where the view cuts the rings).
  double row_scale = 1;
  double sigma_disp = 0;   // display pixel density that κ caps against (pixels/deg²)
  double e_max = 0;        // farthest view direction from the gaze, degrees
  int evaluations = 0;     // column marches the σ0 solve of this frame used
  // The cap follows the rings' densest pixels beyond the fovea, not σ_disp alone: one cap
  // could not pay the budget at some gaze (a wide view, or a budget near the pixel count).
  bool ring_cap = false;
};
std::optional<VisualPolarState> visual_polar_state(const SampleDistribution& d);

// Frisvad / Duff et al. 2017 ("Building an orthonormal basis, revisited"): b1, b2 ⟂ n,
// continuous everywhere except the single point n = (0, 0, −1)·… handled by the sign switch.
void orthonormal_basis(glm::dvec3 n, glm::dvec3& b1, glm::dvec3& b2);

// Halton radical inverse (base 2 or 3) of i: the per-frame jitter sequence.
double halton(std::uint32_t i, std::uint32_t base);

}  // namespace fovea::core
