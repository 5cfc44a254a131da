#pragma once
// Reconstruction in grid space (docs/reconstruction.md): the settings every stage reads.
#include <limits>
#include <string_view>

#include <glm/vec3.hpp>

#include "fovea/core/view.hpp"

#include "fovea/reconstruct/bmfr.hpp"

namespace fovea::reconstruct {

enum class Denoiser { Bmfr, None };
// Off: each eye alone. Gather: each eye also gathers the other eye's accumulated indirect
// diffuse. Alternate: indirect diffuse is traced for one eye per frame (alternating) and
// gathered by the other, halving indirect work.
enum class StereoShare { Off, Gather, Alternate };

Denoiser parse_denoiser(std::string_view s);        // "bmfr" | "none", else InputError
StereoShare parse_stereo_share(std::string_view s);  // "off" | "gather" | "alternate"
const char* denoiser_name(Denoiser d);
const char* stereo_share_name(StereoShare s);

// Peripheral blur from the acuity model (docs/reconstruction.md): the minimum angle of
// resolution MAR(e) = MAR₀ / m(e) (core::acuity::m, P4 Eq. 1; MAR₀ = 1 arcmin, 20/20 vision)
// and a Gaussian whose MTF exp(−2π²σ²f²) is 1/2 at f = 1/MAR(e) cycles per degree:
// σ(e) = √(ln 2 / 2) / π · MAR(e) ≈ 0.187 MAR(e), 0.042° at 30°. Gratings the eye resolves
// (f ≤ 1/(2 MAR)) keep at least 84% of their contrast.
constexpr double kMarFoveaDeg = 1.0 / 60.0;
double blur_sigma_deg(double e_deg, double mar_fovea_deg = kMarFoveaDeg);

struct ReconSettings;

// Convergence (docs/reconstruction.md, "History weights"): the EMA floors (alpha_min,
// post_alpha_min, taa_alpha) keep a moving view's history short, so that what changed shows
// within a few frames. A still view (the same eye poses and gaze; scenes are static) has
// nothing to forget: its history weights become 1/n, a cumulative mean that converges to the
// reference. In between the floors scale with the view's motion per frame, in full from
// kFullFloorMotionDeg on: the cap on n is 1/floor, set by how much the view changed.
constexpr double kFullFloorMotionDeg = 1.0;
// The view's change between two frames in degrees: the gaze's angle, the eye's rotation and
// its translation seen from kMotionParallaxM away (the parallax of a surface at that distance).
constexpr double kMotionParallaxM = 1.0;
// A gaze jump that puts the fovea where there was periphery, and the frames from it that
// trace ReconSettings::landing_spp samples per fovea cell.
constexpr double kLandingJumpDeg = 5.0;
constexpr std::uint32_t kLandingFrames = 4;
// A cell whose area the view moved by less than this share of its size holds the same part
// of the (static) scene as the frame before: its history is the box mean of its own area,
// whichever surfaces the jittered samples hit (shaders/recon_accumulate.comp).
constexpr float kHeldCellShare = 0.1f;
double view_motion_deg(glm::dvec3 gaze_before, glm::dvec3 gaze_now, const core::Pose& before, const core::Pose& now);
ReconSettings with_history_floors(const ReconSettings& s, double motion_deg);

struct ReconSettings {
  Denoiser denoiser = Denoiser::Bmfr;
  BmfrPrecision bmfr_precision = BmfrPrecision::Fp32;  // storage of BMFR's regression matrix
  StereoShare share = StereoShare::Off;
  float alpha_min = 0.2f;        // BMFR Phase I EMA floor
  float post_alpha_min = 0.1f;   // BMFR Phase III EMA floor
  float taa_alpha = 0.2f;        // TAA blend floor (Karis 2014, BMFR), times the jitter's centre weight
  // Cell-size awareness of history and other-eye taps: a tap from a cell up to coarse_keep
  // times the sample's cell size (linear) counts fully, beyond that less, not at all from
  // coarse_reject on. Smooth pursuit changes sizes by < 1.25 per frame at 2.5°/frame; a
  // saccade by far more. Huge values switch the test off (for measuring what it does).
  float coarse_keep = 1.25f, coarse_reject = 2.0f;
  float noise = 0.01f;           // stochastic regularisation ε (BMFR Eq. 7)
  // A new fovea's first frames (docs/reconstruction.md, "A 32° gaze step"): for
  // kLandingFrames frames from one where the gaze jumped by kLandingJumpDeg or more, the
  // cells within the fovea (plus the distribution's margin) trace this many samples (at most
  // 8, the `landing-spp` frame option; 1: off), so that the landed fovea's history fills
  // faster than one sample a frame. 8 with landing_history 2 brings the fovea within 10 % of
  // a still gaze's by the 4th frame; 4 did not (1.09-1.24), and costs the landing's frames
  // less (fove0: +9 % against +20 % GPU time).
  std::uint32_t landing_spp = 8;
  // Textures at the display's resolution near the gaze (the `pixel-albedo` frame option): the
  // frame pipeline traces each display pixel's first hit within the fovea and the margin, and
  // the resolve re-modulates those pixels with their own base colour instead of their cells'
  // (recon_resolve.comp, detail_gain; docs/reconstruction.md, "Textures at the display's
  // resolution"). Only for scenes with textures and grids that are not the display's raster.
  bool pixel_albedo = true;
  // On that jump's frame, Phase I counts the new fovea's history (the periphery's, resampled
  // from another layout) for at most this many samples (huge: its full count), so that the
  // landing's own samples outweigh its blur within a few frames. 2 recovered best of 0, 2, 4
  // and the full count (docs/reconstruction.md, "A 32° gaze step").
  float landing_history = 2;
  // Set per frame by with_history_floors: 1 − the floors' share (1: a still view, which
  // needs no TAA: recon_taa.comp).
  float still = 0;
  // Set per frame by with_history_floors: the view's motion since the last frame (degrees,
  // view_motion_deg). Phase I keeps the history of a cell the view moved by less than
  // kHeldCellShare of its size whatever surfaces its samples hit (recon_accumulate.comp).
  // Unset it is unknown, which counts as moving (as `still` = 0 does): no cell is held.
  float motion_deg = std::numeric_limits<float>::infinity();
  // Set by the frame pipeline on the frame a gaze jump lands (kLandingJumpDeg): the cells
  // within this angle of the gaze (the new fovea and the distribution's margin) take no TAA
  // history this frame. 0: none. That history is the previous frame's periphery, resampled:
  // blended in, it made BMFR's landed fovea worse than no denoiser's (docs/reconstruction.md,
  // "A 32° gaze step").
  float landing_deg = 0;
  // Set by the frame pipeline: the per-cell kernels (accumulation, sharing, post,
  // TAA) run over the cells of the grid pass's live and reset tiles (EyeGrid::live, an
  // indirect dispatch) instead of every cell of the padded grid.
  bool live_cells = false;
  bool block_offsets = true;     // 16 static block-grid displacements
  bool blur = true;              // peripheral blur
  double blur_mar_fovea_deg = kMarFoveaDeg;  // MAR₀ of blur_sigma_deg
  double blur_min_sigma_px = 0.5;            // narrower kernels leave the pixel as it is (sub-pixel: ±1 px weighs ≤ 11%)
  double blur_max_sigma_px = 16;
  // Polar grids: where a cell spans several display pixels the resample reconstructs with the
  // cubic B-spline over four cells instead of the tent over two (recon_grid.h,
  // kReconLatticeFromPx; the `lattice-blur` frame option): the tent's kinks draw the lattice,
  // rings and spokes around the gaze that swim with it (measured: docs/reconstruction.md,
  // "The lattice's rings"). On by default: the periphery sees flicker and motion first.
  bool lattice_blur = true;
  // The full-resolution Cartesian raster (cells = the display's pixels): reconstruct each
  // pixel with a Gaussian over its 3×3 cells (σ = 0.5 px, radius 1.5: pbrt-v4's default film
  // filter, raster_filter_side_weight) instead of its own cell alone (the `raster-filter`
  // frame option, gaussian | box). The tent over polar cells, which are not the pixels, averages
  // about as much noise; box-filtered, the raster is the weaker baseline (docs/measurements.md,
  // "Why Visual-Polar's fovea beats the display's raster"). Off by default: the shipped sweep's
  // baseline.
  bool raster_gaussian = false;
};

// raster_gaussian's weight of each side neighbour along an axis, the centre's 1 − 2× it (before
// renormalising at the raster's border): pbrt-v4's Gaussian filter, exp(−d²/2σ²) − exp(−r²/2σ²)
// for |d| < r, σ = 0.5 px and r = 1.5 px, at d = 0 and ±1 (≈ 0.1004).
double raster_filter_side_weight();

}  // namespace fovea::reconstruct
