#include "render_setup.hpp"

#include "fovea/core/eye_optics.hpp"

namespace fovea::tools {

namespace {
// A budget the display cannot reach is refused naming the display (DistributionParams::display).
core::DistributionParams named(core::DistributionParams p, const core::DisplayPreset& display) {
  p.display = display.origin;
  return p;
}
}  // namespace

RenderSetup::RenderSetup(const renderer::Scene& scene, const core::DisplayPreset& display,
                         const RenderSetupOptions& options)
    : trace_choice(renderer::choose_tracing(ctx, options.tracing, renderer::default_trace_choice_cache())),
      gpu_scene(ctx, scene, {}, trace_choice.tracing),
      views(core::stereo_views(display, scene.camera)),
      poses(views.poses()),
      pipeline(ctx, gpu_scene, views, named(options.distribution, display), options.settings) {
  if (options.cull)
    for (core::Eye e : {core::Eye::Left, core::Eye::Right})
      pipeline.set_visibility(e, core::EyeOptics(display, e).view_mask());
}

}  // namespace fovea::tools
