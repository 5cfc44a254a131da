#pragma once
// Helpers for the pipeline and reconstruction tests: small displays, grid-space references.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/pipeline/testing.hpp"
#include "fovea/core/acuity.hpp"
#include "fovea/core/flip.hpp"
#include "fovea/core/metrics.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/image.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/renderer/path_tracer.hpp"
#include "fovea/renderer/reference.hpp"
#include "fovea/renderer/scene.hpp"
#include "pt_helpers.hpp"

namespace fovea::test {

// The tiny preset's optics at another raster size.
inline core::DisplayPreset display_of_size(int w, int h) {
  core::DisplayPreset d = core::load_display("tiny");
  d.width = w;
  d.height = h;
  return d;
}

// The view-space gaze `deg` degrees to the right of straight ahead (left for negative).
inline glm::dvec3 horizontal_gaze(double deg) {
  const double r = deg * (M_PI / 180);
  return {std::sin(r), 0, -std::cos(r)};
}

// Mean of `frames` frames of 1 spp traced on `grid` (the pipeline's current grid): a
// grid-space reference of the plain radiance and of the demodulated indirect diffuse.
inline Traced trace_reference(gpu::Context& ctx, const renderer::GpuScene& scene,
                              const std::vector<shaders::GridSample>& grid, const core::View& view, core::Eye eye,
                              std::uint32_t frames) {
  return trace_grid(ctx, scene, grid, view, eye, {}, frames, 100000);
}

// Cells as a one-row image (rgb), selected by `keep`.
template <class Keep>
inline core::Image cells_image(const std::vector<glm::vec4>& v, Keep keep) {
  std::vector<glm::vec4> px;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (keep(i)) px.push_back(glm::vec4(glm::vec3(v[i]), 1.0f));
  core::Image img(int(px.size()), 1);
  img.pixels = px;
  return img;
}

// A converged reference of the fovea alone: the pixels within `radius_deg` of `gaze` and the
// margin their FLIP/SSIM neighbourhoods read, at a fraction of the whole view's cost. The
// fovea's scores equal those against a whole reference (its pixels are traced alike) but
// HDR-FLIP's, whose exposure range is then the window's (docs/metrics.md). `o` sets the
// transport, batches and stopping rule.
struct FoveaReference {
  core::Image image;
  std::vector<bool> valid;     // the rendered window
  std::vector<float> weights;  // 1: a fovea pixel, 0: not scored
  double ppd = 0;
};

inline FoveaReference fovea_reference(gpu::Context& ctx, const renderer::GpuScene& gs, const core::View& view,
                                      glm::dvec3 gaze, renderer::ReferenceOptions o,
                                      double radius_deg = core::acuity::kFoveaDeg) {
  FoveaReference r;
  r.ppd = core::flip_ppd(view);
  const int support = core::error_map_support_px(r.ppd);
  o.window.discs.assign(1, {gaze, radius_deg + 1.5 * support / r.ppd});
  r.image = renderer::render_reference(ctx, gs, view, core::Eye::Left, o).image;
  r.valid = renderer::window_coverage(o.window, view, "fovea window");
  const std::vector<bool> scored = core::scorable_pixels(r.valid, view.width(), view.height(), support);
  const std::vector<float> ecc = core::eccentricity_map(view, gaze);
  r.weights.assign(ecc.size(), 0.0f);
  for (std::size_t i = 0; i < ecc.size(); ++i)
    if (scored[i] && ecc[i] <= radius_deg) r.weights[i] = 1.0f;
  return r;
}

// The fovea's scores of `img` against `ref` (tone mapper at exposure 0).
inline core::Scores fovea_scores(const core::Image& img, const FoveaReference& ref) {
  return core::pool(core::error_maps(img, ref.image, ref.ppd, 0.0, ref.valid), ref.weights);
}

inline bool all_finite(const std::vector<glm::vec4>& v) {
  for (const auto& p : v)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.w)) return false;
  return true;
}

}  // namespace fovea::test
