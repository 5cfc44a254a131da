#pragma once
// ꟻLIP image difference, implemented from the papers:
//   LDR-FLIP: Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild 2020, "FLIP: A
//             Difference Evaluator for Alternating Images", Proc. ACM CGIT 3(2) (HPG 2020);
//   HDR-FLIP: Andersson, Nilsson, Shirley, Akenine-Möller 2021, "Visualizing Errors in
//             Rendered High Dynamic Range Images", Eurographics short papers.
// Per-pixel errors in [0, 1]; docs/metrics.md gives every step with its equation.
#include <vector>

#include "fovea/core/image.hpp"
#include "fovea/core/view.hpp"

namespace fovea::core {

// The paper's default: a 0.7 m distant 0.7 m wide 4K monitor, ≈ 67 pixels per degree.
constexpr double kFlipDefaultPpd = 67.0;

// Pixels per degree at the centre of `view`'s raster (the HMD's FOV and resolution).
double flip_ppd(const View& view);

// LDR-FLIP of display-linear RGB images in [0, 1] (values are clamped), per pixel.
// Symmetric in its arguments. Throws InputError on size mismatch or ppd ≤ 0.
std::vector<float> ldr_flip(const Image& test, const Image& reference, double ppd = kFlipDefaultPpd);

// The radius in pixels of the neighbourhood LDR- and HDR-FLIP read around a pixel: the
// widest of the CSF filters and the feature detector at `ppd`.
int flip_support_px(double ppd);

// The weight a pixel's direct neighbour gets relative to the pixel itself in FLIP's widest
// spatial filter (the CSF's b = 0.04 Gaussian, exp(−π²·(1/ppd)²/b)). Below
// kFlipFiltersActiveWeight the filters leave every pixel as it is: FLIP then compares pixel
// by pixel, as it would at a far lower resolution than the display's (below ≈ 6 ppd).
double flip_neighbour_weight(double ppd);
constexpr double kFlipFiltersActiveWeight = 1e-3;

struct HdrFlip {
  std::vector<float> error;  // per pixel, the maximum LDR-FLIP over the exposures
  double start_exposure = 0, stop_exposure = 0;
  int exposures = 0;
};
// HDR-FLIP of linear HDR RGB images: exposures c_start…c_stop (from the reference's maximum
// and median luminance, Andersson et al. 2021 Sec. 3), each pair tone mapped with
// tonemap_linear (tonemap.hpp), LDR-FLIP per exposure, per-pixel maximum. `valid` (one
// flag per pixel; empty: all) limits the pixels the exposure range is taken from, for a
// reference that holds only part of the image.
HdrFlip hdr_flip(const Image& test, const Image& reference, double ppd = kFlipDefaultPpd,
                 const std::vector<bool>& valid = {});

// The exposure range alone: c = log2(t⁻¹(0.85) / Y) for Y = max and median luminance of the
// reference's valid pixels (a median of 0 falls back to the smallest positive luminance),
// N = max(2, ⌈c_stop − c_start⌉) exposures spaced evenly including both ends. InputError
// when no pixel is valid.
HdrFlip hdr_flip_exposures(const Image& reference, const std::vector<bool>& valid = {});

// The colour pipeline's constituents, exposed for tests (inputs linear RGB in [0, 1]):
// Hunt-adjusted CIELab (L, 0.01·L·a, 0.01·L·b) and the HyAB distance |ΔL| + ‖Δ(a, b)‖.
glm::dvec3 flip_hunt_lab(glm::dvec3 linear_rgb);
double flip_hyab(glm::dvec3 hunt_lab_a, glm::dvec3 hunt_lab_b);
// The redistribution of a HyAB distance to [0, 1] (2020, Sec. 4.1 with q_c = 0.7, p_c =
// 0.4, p_t = 0.95, c_max = HyAB of green and blue).
double flip_colour_error(double hyab);

}  // namespace fovea::core
