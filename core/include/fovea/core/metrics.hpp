#pragma once
// Image-quality metrics for the reconstruction, all on linear HDR RGB images of equal size
// (alpha ignored):
//   psnr            10·log10(peak² / MSE), MSE over R, G, B; peak 1 (linear radiance 1 = the
//                   display's white), so HDR values above 1 count with their full error
//   ssim            Wang et al. 2004 on luminance after the stated tone map (Reinhard
//                   c / (1 + L), then sRGB encoding): 11×11 Gaussian window σ = 1.5,
//                   K1 = 0.01, K2 = 0.03, L = 1, mean over the valid (fully covered) windows
//   band_psnr       PSNR per eccentricity band [k·w, (k+1)·w) around the gaze (w = 2°)
//   fovea_psnr      PSNR over pixels with eccentricity <= 5.79° (the acuity plateau)
//   foveated_psnr   PSNR after low-passing both images with an eccentricity-dependent Gaussian
//                   matched to acuity (acuity_sigma_deg), i.e. error the eye can resolve
//   temporal_error  Schied et al. 2017: mean |Y_t − Y_{t−1}| of consecutive frames (Rec. 709
//                   luminance, linear)
// Results are finite: identical images give kPsnrIdentical dB.
#include <vector>

#include <glm/vec3.hpp>

#include "fovea/core/image.hpp"
#include "fovea/core/view.hpp"

namespace fovea::core {

constexpr double kPsnrIdentical = 100.0;  // PSNR reported for MSE below 1e-10

double psnr(const Image& a, const Image& b);
// PSNR over the pixels where mask[i] is true (empty selection: kPsnrIdentical).
double psnr_masked(const Image& a, const Image& b, const std::vector<bool>& mask);
double ssim(const Image& a, const Image& b);
double temporal_error(const Image& previous, const Image& current);

// Eccentricity (degrees) of every pixel centre of `view`'s raster from `gaze` (view space).
std::vector<float> eccentricity_map(const View& view, glm::dvec3 gaze);

struct BandPsnr {
  double e_min = 0, e_max = 0;  // degrees
  long pixels = 0;
  double psnr = kPsnrIdentical;
};
// Bands of `band_deg` from 0 out to the largest eccentricity present; empty bands skipped.
std::vector<BandPsnr> band_psnr(const Image& a, const Image& b, const std::vector<float>& ecc,
                                double band_deg = 2.0);
double fovea_psnr(const Image& a, const Image& b, const std::vector<float>& ecc);

// Standard deviation (degrees) of the Gaussian whose response is 1/2 at the acuity limit
// V(e) = 60·m(e) cycles/degree (Reddy): exp(−2π²σ²V²) = 1/2  =>  σ = √(ln 2 / 2) / (π·V).
double acuity_sigma_deg(double ecc_deg);
// Both images low-passed per pixel with σ = acuity_sigma_deg(e) converted to pixels with the
// view's local pixel density, then PSNR.
double foveated_psnr(const Image& a, const Image& b, const View& view, glm::dvec3 gaze);
// The eccentricity-dependent separable Gaussian used above (exposed for tests): sigma_px
// per pixel; the kernel at each output pixel uses that pixel's σ, weights renormalised at
// the borders.
Image variable_gaussian(const Image& img, const std::vector<float>& sigma_px);

}  // namespace fovea::core
