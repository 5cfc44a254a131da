#pragma once
// Lens parameters of a display preset: the optional "lens" section of its JSON
// (format and the origin of every preset's numbers: docs/display-stage.md).
// Pure data; the optics built from it live in lens.hpp.
#include <array>
#include <string>
#include <string_view>

#include <glm/vec2.hpp>

namespace fovea::core {

enum class LensModelKind { None, Vive, Panotools };

// Vive/Index style, one record per colour channel (r, g, b): in the model's normalised
// panel coordinates t = (2u−1, (2v−1)/aspect) − centre (y down), d(r) = 1/(1 + k1 r² + k2 r⁴
// + k3 r⁶) + k4, source uv = ½ + (t·d + centre)·(f, f·aspect), f = ½/(1 + grow).
struct ViveChannel {
  glm::dvec2 centre{0, 0};
  std::array<double, 4> k{0, 0, 0, 0};  // k1, k2, k3, k4
};
struct ViveLens {
  double aspect = 0.9;        // panel width / height of one eye
  double grow = 0.5;          // grow_for_undistort
  double r2_cutoff = 0;       // 0: no cut-off; else r² beyond it is outside the lens
  std::array<ViveChannel, 3> channel{};
};

// panotools polynomial: p = (panel position − centre)/scale, ρ = |p|,
// ρ → ρ·(k0 + k1 ρ + k2 ρ² + k3 ρ³ + k4 ρ⁴), then scaled by aberration[c] per channel.
// centre in fractions of the panel (x right, y down); scale in panel widths.
struct PanotoolsLens {
  std::array<double, 5> k{1, 0, 0, 0, 0};
  std::array<double, 3> aberration{1, 1, 1};
  glm::dvec2 centre{0.5, 0.5};
  double scale = 0.5;
  double cutoff = 0;  // 0: none; else ρ beyond it is outside the lens
};

// The left eye's lens; the right eye's is its mirror image (x → −x about the panel).
struct LensParams {
  LensModelKind kind = LensModelKind::None;  // None: identity optics, nothing hidden by the lens
  ViveLens vive;
  PanotoolsLens panotools;
  std::string source;  // where the numbers come from (free text from the preset)
};

// Reads the "lens" section of a display preset's JSON text; absent → kind None. Throws
// InputError "<origin>: lens.<field>: …" for malformed, non-finite or degenerate values
// (zero/negative scale, aspect or aberration, grow ≤ −1, a radial map that does not
// increase at the lens centre).
LensParams parse_lens_params(std::string_view preset_json, std::string_view origin);

const char* lens_model_name(LensModelKind k);

}  // namespace fovea::core
