#pragma once
// Image-quality metrics for the reconstruction, all on linear HDR RGB images of equal size
// (alpha ignored):
//   psnr            10·log10(peak² / MSE), MSE over R, G, B; peak 1 (linear radiance 1 = the
//                   display's white), so HDR values above 1 count with their full error
//   ssim            Wang et al. 2004 on the luma (Rec. 709 weights) of tonemap_srgb
//                   (tonemap.hpp): 11×11 Gaussian window σ = 1.5, K1 = 0.01, K2 = 0.03,
//                   L = 1, windows renormalised at the borders, mean of the index map
//   band_psnr       PSNR per eccentricity band [k·w, (k+1)·w) around the gaze (w = 2°)
//   fovea_psnr      PSNR over pixels with eccentricity <= 5.79° (the acuity plateau)
//   foveated_psnr   PSNR after low-passing both images with an eccentricity-dependent Gaussian
//                   matched to acuity (acuity_sigma_deg), i.e. error the eye can resolve
//   temporal_error  Schied et al. 2017: mean |Y_t − Y_{t−1}| of consecutive frames (Rec. 709
//                   luminance, linear)
// Results are finite: identical images give kPsnrIdentical dB.
// The error maps further down (tone-mapped PSNR and SSIM, relMSE, LDR-/HDR-FLIP) pool per
// 2° band and with acuity weights; docs/metrics.md has every formula.
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

// SSIM index per pixel (the map ssim() averages); its window reaches kSsimRadius pixels.
constexpr int kSsimRadius = 5;  // 11×11
std::vector<float> ssim_map(const Image& a, const Image& b);

// Per-pixel error maps of `test` against `reference` (linear HDR RGB, equal sizes).
struct ErrorMaps {
  std::vector<float> squared_error;  // tonemap_srgb at `exposure`, mean over R, G, B
  std::vector<float> ssim;           // ssim_map
  std::vector<float> rel_mse;        // linear: mean over R, G, B of (t − r)² / (r² + kRelMseEpsilon)
  std::vector<float> ldr_flip;       // LDR-FLIP of tonemap_linear at `exposure`
  std::vector<float> hdr_flip;       // HDR-FLIP (flip.hpp) of the linear images
};
constexpr double kRelMseEpsilon = 0.01;
// `valid` (one flag per pixel, empty: all): the reference's pixels that hold values; only
// HDR-FLIP's exposure range reads it (from the valid pixels' luminance). Where a pixel's
// neighbourhood (error_map_support_px) is all valid, its maps are those of any reference
// that agrees on the valid pixels.
ErrorMaps error_maps(const Image& test, const Image& reference, double ppd, double exposure = 0.0,
                     const std::vector<bool>& valid = {});

// The radius in pixels of the square neighbourhood error_maps reads around a pixel: SSIM's
// window and FLIP's filters at `ppd`.
int error_map_support_px(double ppd);
// The pixels whose (2·radius+1)² neighbourhood, clipped to the image, is all valid (an
// erosion of `valid`, width × height, row-major): with radius = error_map_support_px the
// pixels whose error maps a partial reference gives exactly.
std::vector<bool> scorable_pixels(const std::vector<bool>& valid, int width, int height, int radius);

// Weighted means of the maps (weights ≥ 0, one per pixel; empty: all 1). PSNR comes from
// the weighted MSE (peak 1, kPsnrIdentical when it vanishes), the others are means. A zero
// total weight gives the scores of identical images with weight 0.
struct Scores {
  double psnr = kPsnrIdentical, ssim = 1, rel_mse = 0, ldr_flip = 0, hdr_flip = 0;
  double weight = 0;  // Σ weights
};
Scores pool(const ErrorMaps& maps, const std::vector<float>& weights = {});
double weighted_mean(const std::vector<float>& map, const std::vector<float>& weights = {});

// The band k with k·w <= e < (k+1)·w, compared in double as band_scores does (e finite, >= 0).
int band_index(float e, double band_deg);

// Scores per eccentricity band [k·w, (k+1)·w) (empty bands skipped).
struct BandScores {
  double e_min = 0, e_max = 0;
  long pixels = 0;
  Scores scores;
};
std::vector<BandScores> band_scores(const ErrorMaps& maps, const std::vector<float>& ecc, double band_deg = 2.0);

// Foveated pooling weights: the normalised acuity w(e) = m(e) (acuity.hpp, Koskela et al.
// 2018 P4 Eq. 1): 1 within 5.79°, 0.075 at 30°: error counts as much as the eye resolves.
std::vector<float> foveation_weights(const std::vector<float>& ecc);

// Flicker of a static scene: per pixel, the standard deviation over the frames of the luma
// of tonemap_srgb at `exposure` (needs ≥ 2 frames of equal size). Pool it with
// weighted_mean, per band or foveated.
std::vector<float> flicker_map(const std::vector<Image>& frames, double exposure = 0.0);

}  // namespace fovea::core
