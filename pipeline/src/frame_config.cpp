#include "fovea/pipeline/frame_config.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "fovea/core/error.hpp"
#include "fovea/shaders/pt_trace.h"

namespace fovea::pipeline {

static_assert(FrameConfig::kMaxLandingSpp == shaders::kPtMaxSppPerDispatch, "the landing's samples take one dispatch");

reconstruct::ReconSettings FrameConfig::default_recon() {
  reconstruct::ReconSettings s;
  s.share = reconstruct::StereoShare::Gather;
  return s;
}

const std::vector<std::string>& frame_option_names() {
  static const std::vector<std::string> names = {"budget",         "cap",          "distribution", "jitter",
                                                 "denoiser",       "bmfr-precision", "stereo-share", "trace",
                                                 "bounces",        "seed",           "landing-spp",
                                                 "pixel-albedo",   "lattice-blur",   "raster-filter"};
  return names;
}

namespace {
// A whole number in [lo, hi] written in full; otherwise InputError "expected [or_what]a whole
// number in lo..hi, got "value"".
long whole_number(std::string_view value, long lo, long hi, const char* or_what = "") {
  const std::string v(value);
  char* end = nullptr;
  errno = 0;
  const long n = std::strtol(v.c_str(), &end, 10);
  if (v.empty() || *end != '\0' || errno == ERANGE || n < lo || n > hi)
    throw core::InputError(std::string("expected ") + or_what + "a whole number in " + std::to_string(lo) + ".." +
                           std::to_string(hi) + ", got \"" + v + "\"");
  return n;
}

// "on" or "off"; otherwise InputError "expected on or off, got "value"".
bool on_off(std::string_view value) {
  if (value != "on" && value != "off") throw core::InputError("expected on or off, got \"" + std::string(value) + "\"");
  return value == "on";
}

// A finite number written in full; otherwise InputError "expected a finite number, got "value"".
double finite_number(std::string_view value) {
  const std::string v(value);
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(v.c_str(), &end);
  if (v.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(x))
    throw core::InputError("expected a finite number, got \"" + v + "\"");
  return x;
}
}  // namespace

void apply_frame_option(FrameConfig& c, std::string_view name, std::string_view value, const std::string& where) {
  try {
    if (name == "budget") {
      c.distribution.budget = finite_number(value);
    } else if (name == "cap") {
      c.distribution.cap = finite_number(value);  // its range: finish() (DistributionParams::validate)
    } else if (name == "distribution") {
      c.distribution.kind = core::parse_distribution(value);
    } else if (name == "jitter") {
      c.distribution.jitter = core::parse_jitter(value);
    } else if (name == "denoiser") {
      c.recon.denoiser = reconstruct::parse_denoiser(value);
    } else if (name == "bmfr-precision") {
      if (value != "fp32" && value != "fp16")
        throw core::InputError("expected fp32 or fp16, got \"" + std::string(value) + "\"");
      c.recon.bmfr_precision = value == "fp16" ? reconstruct::BmfrPrecision::Fp16 : reconstruct::BmfrPrecision::Fp32;
    } else if (name == "stereo-share") {
      c.recon.share = reconstruct::parse_stereo_share(value);
    } else if (name == "trace") {
      c.tracing = renderer::parse_tracing(value, "--trace");
    } else if (name == "bounces") {
      if (value == "auto") c.bounces.from_albedo = true;
      else c.bounces = {false, int(whole_number(value, 0, Bounces::kMaxBounces, "auto or "))};
    } else if (name == "landing-spp") {
      c.recon.landing_spp = std::uint32_t(whole_number(value, 1, FrameConfig::kMaxLandingSpp));
    } else if (name == "pixel-albedo") {
      c.recon.pixel_albedo = on_off(value);
    } else if (name == "lattice-blur") {
      c.recon.lattice_blur = on_off(value);
    } else if (name == "raster-filter") {
      if (value != "box" && value != "gaussian")
        throw core::InputError("expected box or gaussian, got \"" + std::string(value) + "\"");
      c.recon.raster_gaussian = value == "gaussian";
    } else if (name == "seed") {
      c.seed = std::uint32_t(whole_number(value, 0, FrameConfig::kMaxSeed));
    } else {
      throw core::InputError("not a frame option");
    }
  } catch (const core::InputError& e) {
    // The parsers name the command-line option ("--jitter: ..."): the caller's `where` replaces it.
    std::string what = e.what();
    const std::string option = "--" + std::string(name) + ": ";
    if (what.rfind(option, 0) == 0) what = what.substr(option.size());
    throw core::InputError(where + ": " + what);
  }
}

void finish(FrameConfig& c, bool budget_given) {
  if (c.distribution.kind == core::DistributionKind::Cartesian) {
    if (budget_given && c.distribution.budget != 1.0)
      throw core::InputError("budget: cartesian traces every pixel (budget 1); use cartesian-uniform for a fraction of "
                             "the pixels");
    c.distribution.budget = 1.0;
  }
  if (c.distribution.kind != core::DistributionKind::VisualPolar && c.distribution.cap != core::DistributionParams{}.cap)
    throw core::InputError(std::string("cap: only visual-polar caps its samples per pixel, not ") +
                           core::distribution_name(c.distribution.kind));
  if (c.recon.raster_gaussian && c.distribution.kind != core::DistributionKind::Cartesian)
    throw core::InputError(std::string("raster-filter: only cartesian's cells are the display's pixels; ") +
                           core::distribution_name(c.distribution.kind) + " reconstructs its cells with the tent");
  c.distribution.validate();
}

nlohmann::json to_json(const FrameConfig& c) {
  return {{"distribution", core::distribution_name(c.distribution.kind)},
          {"budget", c.distribution.budget},
          {"cap", c.distribution.cap},
          {"jitter", c.distribution.jitter ? "on" : "off"},
          {"denoiser", reconstruct::denoiser_name(c.recon.denoiser)},
          {"bmfr-precision", c.recon.bmfr_precision == reconstruct::BmfrPrecision::Fp16 ? "fp16" : "fp32"},
          {"stereo-share", reconstruct::stereo_share_name(c.recon.share)},
          {"trace", renderer::tracing_name(c.tracing)},
          {"bounces", c.bounces.from_albedo ? nlohmann::json("auto") : nlohmann::json(c.bounces.count)},
          {"seed", c.seed},
          {"landing-spp", c.recon.landing_spp},
          {"pixel-albedo", c.recon.pixel_albedo ? "on" : "off"},
          {"lattice-blur", c.recon.lattice_blur ? "on" : "off"},
          {"raster-filter", c.recon.raster_gaussian ? "gaussian" : "box"}};
}

renderer::PathConfig path_config(const Bounces& bounces, const renderer::Scene& scene) {
  if (bounces.from_albedo) return renderer::albedo_path_config(renderer::albedo_stats(scene));
  renderer::PathConfig p;
  p.max_bounces = bounces.count;
  return p;
}

nlohmann::json transport_json(const renderer::PathConfig& path, const std::string& rule) {
  const bool roulette = path.rr_start <= std::uint32_t(Bounces::kMaxBounces);
  return {{"bounces", path.max_bounces < 0 ? nlohmann::json("unlimited") : nlohmann::json(path.max_bounces)},
          {"rr_start", roulette ? nlohmann::json(path.rr_start) : nlohmann::json()},
          {"rule", rule}};
}

}  // namespace fovea::pipeline
