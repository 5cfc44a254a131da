#pragma once
// Reconstruction in grid space (docs/reconstruction.md): the settings every stage reads.
#include <string_view>

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

// P5 §3.5: σ = 6.8 px at 30° on the FOVE 0 panel (1280×1440, 100° wide), whose horizontal
// density at 30° is 12.5 px/° (f·sec²30° with f = 640 / tan 50° px): 6.8 / 12.5 = 0.544°.
constexpr double kBlurSigmaDegAt30 = 0.544;

struct ReconSettings {
  Denoiser denoiser = Denoiser::Bmfr;
  BmfrPrecision bmfr_precision = BmfrPrecision::Fp32;  // storage of BMFR's regression matrix
  StereoShare share = StereoShare::Off;
  float alpha_min = 0.2f;        // BMFR Phase I EMA floor
  float post_alpha_min = 0.1f;   // BMFR Phase III EMA floor
  float taa_alpha = 0.2f;        // TAA blend (Karis 2014 / BMFR reference)
  float noise = 0.01f;           // stochastic regularisation ε (BMFR Eq. 7)
  bool block_offsets = true;     // 16 static block-grid displacements
  bool blur = true;              // peripheral blur
  double blur_fovea_deg = 5.79;  // blur starts at the acuity plateau's edge
  double blur_sigma_deg_at_30 = kBlurSigmaDegAt30;
  double blur_max_sigma_px = 16;
};

}  // namespace fovea::reconstruct
