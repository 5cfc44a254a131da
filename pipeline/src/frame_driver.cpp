#include "fovea/pipeline/frame_driver.hpp"

#include "fovea/core/eye_optics.hpp"

namespace fovea::pipeline {

namespace {
// A budget the display cannot reach is refused naming the display (DistributionParams::display).
core::DistributionParams named(core::DistributionParams p, const std::optional<core::DisplayPreset>& display) {
  if (display) p.display = display->origin;
  return p;
}
}  // namespace

FrameDriver::FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::DisplayPreset& display,
                         const FrameDriverOptions& options)
    : FrameDriver(ctx, scene, core::stereo_views(display, scene.camera), options, display) {}

FrameDriver::FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::StereoViews& views,
                         const FrameDriverOptions& options)
    : FrameDriver(ctx, scene, views, options, std::nullopt) {}

FrameDriver::FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::StereoViews& views,
                         const FrameDriverOptions& options, const std::optional<core::DisplayPreset>& display)
    : frame_(options.frame),
      camera_(scene.camera),
      trace_choice_(renderer::choose_tracing(ctx, frame_.tracing, renderer::default_trace_choice_cache(),
                                             options.measure_trace)),
      gpu_scene_(ctx, scene, renderer::BvhOptions{}, trace_choice_.tracing),
      views_(views),
      pipeline_(ctx, gpu_scene_, views_, named(frame_.distribution, display), frame_.recon,
                path_config(frame_.bounces, scene)) {
  if (display && options.cull)
    for (core::Eye e : {core::Eye::Left, core::Eye::Right})
      pipeline_.set_visibility(e, core::EyeOptics(*display, e).view_mask());
}

core::Pose FrameDriver::at_camera(const core::Pose& eye) const {
  core::Pose p;
  p.orientation = camera_.orientation * eye.orientation;
  p.position = camera_.position + camera_.orientation * eye.position;
  return p;
}

}  // namespace fovea::pipeline
