#pragma once
// Progressive Cartesian reference rendering of one eye: batches of samples per pixel
// accumulated on the GPU until a sample count or a relative standard error is reached.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "fovea/core/image.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/path_tracer.hpp"

namespace fovea::renderer {

// The part of a view a reference renders: the union of discs on the view sphere, each the
// pixels whose centre lies within radius_deg of a view-space direction (the gaze, say).
// No discs: the whole view.
struct WindowDisc {
  glm::dvec3 centre{0, 0, -1};  // view space, any finite non-zero length
  double radius_deg = 0;        // in (0, 180]
};
struct ReferenceWindow {
  std::vector<WindowDisc> discs;
  bool whole() const { return discs.empty(); }
};

// One flag per pixel of `view`'s raster (row-major): its centre inside a disc of `window`
// (all true for the whole view). InputError starting with `what` (the input's name) for a
// disc with a non-finite or zero centre, a radius outside (0, 180] or not finite, or one
// that holds no pixel centre of the view.
std::vector<bool> window_coverage(const ReferenceWindow& window, const core::View& view, const std::string& what);

struct ReferenceOptions {
  PathConfig path;                  // path.spp = samples per batch; jitter is forced on
  std::uint32_t max_spp = 256;      // stop at this many samples per pixel
  double until_rel_error = 0;       // > 0: stop earlier once rel_error <= this (>= 4 batches)
  double until_pixel_rel_error = 0; // > 0: stop earlier once pixel_rel_error <= this (>= 4 batches)
  ReferenceWindow window;           // the pixels traced; the others are never traced
};

struct ReferenceProgress {
  std::uint32_t spp = 0;
  double rel_error = 0;        // NaN until two batches exist
  double pixel_rel_error = 0;  // NaN until two batches exist
  double seconds = 0;
};

// Every statistic is over the window's pixels.
struct ReferenceResult {
  core::Image image;  // linear radiance, alpha 1 in the window; outside it RGBA 0 (not traced)
  std::uint32_t spp = 0;
  glm::dvec3 mean_rgb{0};
  // Relative standard error of the image-mean luminance, from the spread of the
  // per-batch image means (batch-means estimator). Both errors are NaN (unknown, null in
  // JSON) after a single batch.
  double rel_error = 0;
  // √(mean over pixels of se² / (Y² + 0.01)), se the standard error of the pixel's
  // luminance Y from its batch means: the reference's own expected relMSE (core/metrics'
  // form), rooted — the noise left in the pixels, not only in the image mean.
  double pixel_rel_error = 0;
  double seconds = 0;
};

ReferenceResult render_reference(gpu::Context& ctx, const GpuScene& scene, const core::View& view, core::Eye eye,
                                 const ReferenceOptions& options,
                                 const std::function<void(const ReferenceProgress&)>& progress = {});

// OpenEXR, 32-bit float RGBA, written through a temporary file and renamed.
void write_exr(const std::string& path, const core::Image& img);
// Reads an RGBA OpenEXR file; InputError naming the file when it cannot be read or holds
// non-finite values.
core::Image read_exr(const std::string& path);
// Tone map for display: core::tonemap_linear (exposure 0, the ACES fit the metrics use,
// docs/metrics.md), alpha 1; write_png adds the sRGB OETF.
core::Image tone_map(const core::Image& linear);

}  // namespace fovea::renderer
