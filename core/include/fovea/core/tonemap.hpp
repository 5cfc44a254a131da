#pragma once
// The one display transform of the metrics: exposure 2^c, the ACES filmic curve as fitted
// by Narkowicz (2015) with the 0.6 input scale HDR-FLIP uses (Andersson et al. 2021, Sec. 2):
//   t(x) = (k0·x² + k1·x) / (k3·x² + k4·x + k5), k0 = 0.6²·2.51, k1 = 0.6·0.03,
//   k3 = 0.6²·2.43, k4 = 0.6·0.59, k5 = 0.14,
// per linear-RGB channel, clamped to [0, 1] (display-linear), then the sRGB OETF (IEC
// 61966-2-1) for PSNR/SSIM. Linear radiance 1 at exposure 0 shows as 0.673 (sRGB 0.84).
#include <glm/vec3.hpp>

#include "fovea/core/image.hpp"

namespace fovea::core {

struct AcesCoefficients {
  static constexpr double k0 = 0.6 * 0.6 * 2.51, k1 = 0.6 * 0.03, k2 = 0.0;
  static constexpr double k3 = 0.6 * 0.6 * 2.43, k4 = 0.6 * 0.59, k5 = 0.14;
};

// t(x) unclamped, x ≥ 0.
double aces(double x);
// The x ≥ 0 with t(x) = y (0 ≤ y < k0/k3): the positive root of (y·k3 − k0)x² + (y·k4 − k1)x
// + y·k5 − k2 = 0.
double aces_inverse(double y);

// Display-linear [0, 1]: clamp(t(2^exposure · c)); non-finite channels count as 0.
glm::vec3 tonemap_linear(glm::vec3 rgb, double exposure = 0.0);
// sRGB-encoded [0, 1]: the OETF of tonemap_linear.
glm::vec3 tonemap_srgb(glm::vec3 rgb, double exposure = 0.0);
// Whole images (alpha kept).
Image tonemap_linear(const Image& img, double exposure = 0.0);
Image tonemap_srgb(const Image& img, double exposure = 0.0);

}  // namespace fovea::core
