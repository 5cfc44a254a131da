#include "render_setup.hpp"

#include <algorithm>

#include "fovea/core/eye_optics.hpp"

namespace fovea::tools {

namespace {
// A budget the display cannot reach is refused naming the display (DistributionParams::display).
core::DistributionParams named(core::DistributionParams p, const core::DisplayPreset& display) {
  p.display = display.origin;
  return p;
}
}  // namespace

pipeline::FrameConfig frame_config_of(const Args& args, const std::vector<std::string>& not_frame) {
  pipeline::FrameConfig c;
  for (const std::string& name : pipeline::frame_option_names())
    if (std::find(not_frame.begin(), not_frame.end(), name) == not_frame.end())
      if (auto v = args.opt(name)) pipeline::apply_frame_option(c, name, *v, "--" + name);
  try {
    pipeline::finish(c, args.has("budget"));
  } catch (const core::InputError& e) {
    throw core::InputError(std::string("--") + e.what());  // "--budget: must be in ..."
  }
  return c;
}

RenderSetup::RenderSetup(const renderer::Scene& scene, const core::DisplayPreset& display,
                         const RenderSetupOptions& options)
    : trace_choice(renderer::choose_tracing(ctx, options.frame.tracing, renderer::default_trace_choice_cache())),
      gpu_scene(ctx, scene, {}, trace_choice.tracing),
      views(core::stereo_views(display, scene.camera)),
      poses(views.poses()),
      pipeline(ctx, gpu_scene, views, named(options.frame.distribution, display), options.frame.recon,
               pipeline::path_config(options.frame.bounces, scene)) {
  if (options.cull)
    for (core::Eye e : {core::Eye::Left, core::Eye::Right})
      pipeline.set_visibility(e, core::EyeOptics(display, e).view_mask());
}

}  // namespace fovea::tools
