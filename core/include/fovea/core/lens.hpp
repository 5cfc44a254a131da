#pragma once
// One eye's lens optics as pure functions (the split Monado uses): a display position maps
// to one source direction per colour channel in the rendered view's tangent space, and back.
//
// Conventions (docs/display-stage.md):
// - The panel has the preset's per-eye raster; display uv ∈ [0,1]², x right, y down.
// - The preset's FOV is the rendered view's FOV (what the runtime reports to applications).
//   A model's native source uv ∈ [0,1]² spans that FOV; it is converted to tangents
//   (x right, y up, on the z = −1 plane) at this API boundary.
// - Display pixels whose source leaves the FOV, or whose radius passes the lens cut-off or
//   the point where the radial map stops increasing, are outside (hidden_area.hpp).
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "fovea/core/display.hpp"
#include "fovea/core/lens_params.hpp"
#include "fovea/core/view.hpp"

namespace fovea::core {

struct LensSample {
  std::array<glm::dvec2, 3> tangent;  // r, g, b source tangents (x right, y up)
  bool within_lens = true;            // false beyond the cut-off / monotonic edge for some channel
};

class Lens {
 public:
  // One channel in the model-independent form both models reduce to:
  //   t = (uv − display_centre) ⊙ to_radial,  r = |t|,
  //   source_uv = source_centre + from_radial ⊙ t·R(r),  R(r) from the model's profile.
  struct Channel {
    glm::dvec2 display_centre, to_radial, source_centre, from_radial;
    bool vive_profile = false;        // R(r) = 1/(1 + k0 r² + k1 r⁴ + k2 r⁶) + k3, else Σ k_i rⁱ
    std::array<double, 5> k{1, 0, 0, 0, 0};
    double r_edge = 0;                // radius beyond which the channel is outside the lens
  };

  // A lens must show the FOV on at least this fraction of its panel, else it is refused.
  static constexpr double kMinVisibleFraction = 0.01;

  Lens() = default;
  // Throws InputError (naming `name`) if the lens leaves no usable region: the radial map
  // ends within 2% of the panel radius, or under kMinVisibleFraction of the panel shows the FOV.
  Lens(const LensParams& params, const View& view, Eye eye, const std::string& name = "lens");
  static Lens for_eye(const DisplayPreset& d, Eye eye);

  const View& view() const { return view_; }
  LensModelKind kind() const { return kind_; }
  const Channel& channel(int c) const { return ch_[c]; }
  // Informational messages, e.g. where the radial map stops increasing inside the panel.
  const std::vector<std::string>& notes() const { return notes_; }

  // Forward optics: display uv → per-channel source tangent. Always finite; beyond a
  // channel's edge the map continues with the edge's radial scale and within_lens is false.
  LensSample forward(glm::dvec2 display_uv) const;
  // Source uv of channel c in the rendered view ([0,1]² = the FOV), same finiteness rule.
  glm::dvec2 source_uv(int c, glm::dvec2 display_uv) const;
  // Inverse optics: a source tangent → the display uv channel c shows it at (may lie off the
  // panel), or nullopt if only radii beyond the channel's edge could show it. Newton
  // iteration on the 1-D radial map, kept inside a shrinking bracket (bisection fallback).
  std::optional<glm::dvec2> inverse(int c, glm::dvec2 tangent) const;

  glm::dvec2 uv_to_tangent(glm::dvec2 uv) const;
  glm::dvec2 tangent_to_uv(glm::dvec2 t) const;

  // Radial map g(r) = r·R(r) and its derivative for channel c.
  double radial(int c, double r) const;
  double radial_derivative(int c, double r) const;

 private:
  void check_visible_area(const std::string& name, Eye eye) const;
  View view_;
  LensModelKind kind_ = LensModelKind::None;
  std::array<Channel, 3> ch_{};
  std::vector<std::string> notes_;
};

}  // namespace fovea::core
