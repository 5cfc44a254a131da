#include "fovea/reconstruct/settings.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "fovea/core/acuity.hpp"
#include "fovea/core/error.hpp"

namespace fovea::reconstruct {

Denoiser parse_denoiser(std::string_view s) {
  if (s == "bmfr") return Denoiser::Bmfr;
  if (s == "none") return Denoiser::None;
  throw core::InputError("--denoiser: unknown \"" + std::string(s) + "\" (expected bmfr|none)");
}

StereoShare parse_stereo_share(std::string_view s) {
  if (s == "off") return StereoShare::Off;
  if (s == "gather") return StereoShare::Gather;
  if (s == "alternate") return StereoShare::Alternate;
  throw core::InputError("--stereo-share: unknown \"" + std::string(s) + "\" (expected off|gather|alternate)");
}

double blur_sigma_deg(double e_deg, double mar_fovea_deg) {
  return std::sqrt(std::numbers::ln2 / 2) / std::numbers::pi * mar_fovea_deg / core::acuity::m(e_deg);
}

const char* denoiser_name(Denoiser d) { return d == Denoiser::Bmfr ? "bmfr" : "none"; }

const char* stereo_share_name(StereoShare s) {
  switch (s) {
    case StereoShare::Gather: return "gather";
    case StereoShare::Alternate: return "alternate";
    default: return "off";
  }
}

}  // namespace fovea::reconstruct
