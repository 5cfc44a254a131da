#pragma once
// What every entry point of the pipeline — `fovea render`, `view`, `latency` and the OpenXR
// layer — configures about a foveated frame, with every default defined here once: the
// sample distribution, its budget and Visual-Polar's cap on samples per pixel, jitter, the
// denoiser and its precision, stereo sharing, the traversal, the light transport (bounces).
// Each entry point starts from FrameConfig{} and applies its options by the same names
// (`--budget 0.2` on the command line, "budget": 0.2 in the layer's file).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "fovea/core/distribution.hpp"
#include "fovea/reconstruct/settings.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/path_tracer.hpp"
#include "fovea/renderer/scene.hpp"

namespace fovea::pipeline {

// The light transport traced: a fixed number of BSDF-sampled bounces after the primary hit
// (no Russian roulette), or `auto`, the bounce limit and Russian roulette the scene's albedo
// calls for (renderer::albedo_path_config, the rule converged references use).
struct Bounces {
  bool from_albedo = false;  // auto
  int count = 1;             // 0..kMaxBounces when not auto: the BMFR/P5 configuration's one bounce
  static constexpr int kMaxBounces = 256;
};

struct FrameConfig {
  core::DistributionParams distribution;  // visual-polar, budget 0.39, jitter on (core's defaults)
  reconstruct::ReconSettings recon = default_recon();
  renderer::Tracing tracing = renderer::Tracing::Auto;
  Bounces bounces;
  // The noise: frame i's random numbers (path tracing, BMFR's block offsets) are keyed by
  // i + FramePipeline::kSeedStride·seed, so another seed is another realisation of the same
  // frames (the same gaze and jitter pattern): repeated runs measure a score's noise.
  std::uint32_t seed = 0;
  static constexpr std::uint32_t kMaxSeed = 1'000'000;
  // recon.landing_spp (`landing-spp`): samples per cell in a new fovea's first frames after a
  // gaze jump, 1 (off) up to what one trace dispatch takes.
  static constexpr std::uint32_t kMaxLandingSpp = 8;

  // BMFR at fp32, the peripheral blur, and stereo sharing by gather: the reconstruction a
  // render shows (ReconSettings{} itself leaves sharing off, for the stage tests).
  static reconstruct::ReconSettings default_recon();
};

// The option names, shared by the command line (--NAME VALUE) and the layer's configuration
// ("NAME": VALUE): budget, cap, distribution, jitter, denoiser, bmfr-precision, stereo-share,
// trace, bounces, seed, landing-spp, pixel-albedo, lattice-blur, raster-filter.
const std::vector<std::string>& frame_option_names();

// Sets option `name` from its text `value`; core::InputError naming `where` (e.g. "--budget",
// "layer.json: default.budget") and the accepted values. The distribution's own constraints
// (the budget's range, the cap's, Cartesian's budget of 1) are checked by finish().
void apply_frame_option(FrameConfig& c, std::string_view name, std::string_view value, const std::string& where);

// After the options: Cartesian traces every pixel (budget 1; a smaller one explicitly given is
// refused, cartesian-uniform's job), a cap other than the default is refused for any
// distribution but visual-polar (the others have none), then DistributionParams::validate().
void finish(FrameConfig& c, bool budget_given);

// The configuration by the option names, for reports (report.json's config, the layer's log).
nlohmann::json to_json(const FrameConfig& c);

// The path tracer's configuration for `scene`: `bounces` resolved (auto: from its albedo).
renderer::PathConfig path_config(const Bounces& bounces, const renderer::Scene& scene);

// A transport for reports: {"bounces": N or "unlimited", "rr_start": N or null, "rule": ...}.
nlohmann::json transport_json(const renderer::PathConfig& path, const std::string& rule);

}  // namespace fovea::pipeline
