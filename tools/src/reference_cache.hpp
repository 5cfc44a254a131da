#pragma once
// Converged references of one eye, cached on disk so that runs and sweep jobs do not pay for
// them again. An entry is <key>.exr (linear RGBA, float) with <key>.json beside it, which
// records the key, everything the key hashes and the stop statistics; the JSON is written
// last, so an entry without it is incomplete and ignored. `fovea reference` and `fovea render
// --reference SPP` both come here with reference_defaults(), so either reuses the other's
// entries. docs/metrics.md, "Reference".
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "fovea/core/view.hpp"
#include "fovea/renderer/reference.hpp"
#include "fovea/renderer/scene.hpp"

namespace fovea::tools {

// What the image depends on besides scene and view; every field is part of the cache key.
// Start from reference_defaults(scene) to share entries with `render` and `reference`.
struct ReferenceSettings {
  std::uint32_t max_spp = 256;
  std::uint32_t batch = 16;
  int bounces = -1;  // < 0: unbounded, Russian roulette alone from rr_start
  std::uint32_t rr_start = 3;
  double until_rel_error = 0;        // image-mean luminance; 0: off
  double until_pixel_rel_error = 0;  // RMS of the per-pixel standard errors; 0: off
};

// The defaults both commands share: 256 spp in batches of 16, bounces and Russian roulette
// from the scene's albedo (renderer::albedo_path_config), stop once the per-pixel relative
// error is <= 0.02.
inline constexpr double kDefaultPixelRelError = 0.02;
ReferenceSettings reference_defaults(const renderer::Scene& scene);
// The defaults with a render's light transport (bounces, Russian roulette): the reference
// its scores compare against (docs/metrics.md, "What is compared with what").
ReferenceSettings reference_settings(const renderer::Scene& scene, const renderer::PathConfig& transport);

// `dir` empty: no cache. `scene` is the --scene argument (a file's bytes are hashed). A
// window (part of the key) renders only its pixels; an entry of the whole view with the
// same settings serves it too.
struct ReferenceRequest {
  std::string scene;
  ReferenceSettings settings;
  renderer::ReferenceWindow window;
  std::string cache_dir;
};

struct CachedReference {
  renderer::ReferenceResult result;
  std::string key;         // 16 hex digits
  std::string identity;    // the canonical JSON the key hashes
  bool from_cache = false;
  renderer::ReferenceWindow window;  // what the image holds (whole: every pixel)
  std::vector<bool> valid;           // per pixel, the window's; empty when whole
};

// A window given on the command line as DISC[;DISC...], DISC = CENTRE@RADIUS (degrees),
// CENTRE = X,Y,Z (a view-space direction: -Z forward, +Y up) or px:X,Y (a display pixel
// position of `view`, origin top-left, y down). Checked against `view`: InputError naming
// `option` for bad syntax, bad numbers and discs off the view.
renderer::ReferenceWindow parse_window(const std::string& spec, const core::View& view, const std::string& option);

// The window as JSON, [{"centre": [x, y, z] (unit), "radius_deg": r}, ...]; null when whole.
nlohmann::json window_json(const renderer::ReferenceWindow& window);

// $XDG_CACHE_HOME/fovea/references, else $HOME/.cache/fovea/references, else
// out/reference-cache.
std::string default_reference_cache();
// "off" -> "", otherwise the directory itself; absent -> default_reference_cache().
std::string reference_cache_arg(const std::string* value);

CachedReference cached_reference(gpu::Context& ctx, const renderer::GpuScene& scene, const core::View& view,
                                 core::Eye eye, const ReferenceRequest& request,
                                 const std::function<void(const renderer::ReferenceProgress&)>& progress = {});

// Writes `exr` and its description `<exr without extension>.json` (atomically, JSON last).
void write_reference(const std::string& exr, const CachedReference& ref);
// Reads a reference written by write_reference and checks that it shows `view` of `scene`
// from `eye`, and for a window that its alpha marks the window's pixels (InputError naming
// the file otherwise).
CachedReference read_reference(const std::string& exr, const std::string& scene, const core::View& view, core::Eye eye);

}  // namespace fovea::tools
