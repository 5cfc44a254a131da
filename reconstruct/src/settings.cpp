#include "fovea/reconstruct/settings.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>
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

double raster_filter_side_weight() {
  static const double side = [] {  // a constant: computed once, not on every frame's resample
    constexpr double sigma = 0.5, radius = 1.5;
    const auto gauss = [](double d) { return std::exp(-d * d / (2 * sigma * sigma)); };
    const auto g = [&](double d) { return gauss(d) - gauss(radius); };
    return g(1) / (g(0) + 2 * g(1));
  }();
  return side;
}

double view_motion_deg(glm::dvec3 gaze_before, glm::dvec3 gaze_now, const core::Pose& before, const core::Pose& now) {
  // The relative rotation's angle: 2·acos|w| of q_now · q_before⁻¹ (|w| folds q and −q).
  const double w = std::min(1.0, std::abs((now.orientation * glm::inverse(before.orientation)).w));
  const double rotation = 2.0 * std::acos(w) * 180.0 / std::numbers::pi;
  const double parallax = std::atan2(glm::length(now.position - before.position), kMotionParallaxM) * 180.0 / std::numbers::pi;
  const double m = core::angle_deg(gaze_before, gaze_now) + rotation + parallax;
  return std::isfinite(m) ? m : kFullFloorMotionDeg;  // an unknown change counts as a full one
}

ReconSettings with_history_floors(const ReconSettings& s, double motion_deg) {
  const float k = float(std::clamp(motion_deg / kFullFloorMotionDeg, 0.0, 1.0));
  ReconSettings r = s;
  r.alpha_min *= k;
  r.post_alpha_min *= k;
  r.taa_alpha *= k;
  r.still = 1.0f - k;
  r.motion_deg = float(std::isfinite(motion_deg) ? std::max(motion_deg, 0.0) : kFullFloorMotionDeg);
  return r;
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
