#include "fovea/pipeline/frame_driver.hpp"

#include <cmath>
#include <stdexcept>

#include "fovea/core/clock.hpp"
#include "fovea/core/eye_optics.hpp"

namespace fovea::pipeline {

namespace {
// A budget the display cannot reach is refused naming the display (DistributionParams::display).
core::DistributionParams named(core::DistributionParams p, const std::optional<core::DisplayPreset>& display) {
  if (display) p.display = display->origin;
  return p;
}

// The lens' hidden area, culled from the first frame on (and each eye's grid laid out for the
// pixels it leaves).
EyeMasks culled(const core::DisplayPreset& display, bool cull) {
  EyeMasks m;
  if (cull)
    for (core::Eye e : {core::Eye::Left, core::Eye::Right}) m[size_t(e)] = core::EyeOptics(display, e).view_mask();
  return m;
}
}  // namespace

FrameDriver::FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::DisplayPreset& display,
                         const FrameDriverOptions& options)
    : FrameDriver(ctx, scene, core::stereo_views(display, scene.camera), options, display,
                  culled(display, options.cull)) {}

FrameDriver::FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::StereoViews& views,
                         const FrameDriverOptions& options, const EyeMasks& visibility)
    : FrameDriver(ctx, scene, views, options, std::nullopt, visibility) {}

FrameDriver::FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::StereoViews& views,
                         const FrameDriverOptions& options, const std::optional<core::DisplayPreset>& display,
                         const EyeMasks& visibility)
    : ctx_(ctx),
      frame_(options.frame),
      refresh_hz_(display ? display->refresh_hz : 0),
      camera_(scene.camera),
      trace_choice_(renderer::choose_tracing(ctx, frame_.tracing, renderer::default_trace_choice_cache(),
                                             options.measure_trace)),
      gpu_scene_(ctx, scene, renderer::BvhOptions{}, trace_choice_.tracing),
      views_(views),
      distribution_(named(frame_.distribution, display)),
      path_(path_config(frame_.bounces, scene)) {
  set_visibility(visibility);
}

void FrameDriver::set_visibility(const EyeMasks& visibility) {
  pipeline_.reset();  // its device memory first
  pipeline_.emplace(ctx_, gpu_scene_, views_, distribution_, frame_.recon, path_, false, visibility);
  pipeline_->set_seed(frame_.seed);
  if (depth_output_) pipeline_->enable_depth_output();
}

void FrameDriver::enable_depth_output() {
  depth_output_ = true;
  if (pipeline_) pipeline_->enable_depth_output();
}

core::Pose FrameDriver::at_camera(const core::Pose& eye) const {
  core::Pose p;
  p.orientation = camera_.orientation * eye.orientation;
  p.position = camera_.position + camera_.orientation * eye.position;
  return p;
}

void FrameDriver::set_gaze(std::unique_ptr<devices::FoveationGaze> gaze) {
  if (refresh_hz_ <= 0) throw std::logic_error("FrameDriver::set_gaze: a driver of given views has no frame timeline");
  gaze_ = std::move(gaze);
}

core::TimeNs frame_time_ns(std::uint32_t index, double refresh_hz) {
  return core::TimeNs(std::llround(double(index) / refresh_hz * 1e9));
}

DrivenFrame FrameDriver::step(std::uint32_t index) {
  if (!gaze_) throw std::logic_error("FrameDriver::step: no gaze source (set_gaze)");
  const core::TimeNs t0 = core::now_ns();
  const devices::FoveaGaze g = gaze_->at_frame_time(frame_ns(index));
  return step(index, g, static_poses(), core::ns_to_ms(core::now_ns() - t0));
}

DrivenFrame FrameDriver::step(std::uint32_t index, const devices::FoveaGaze& gaze, const std::array<core::Pose, 2>& poses,
                              double gaze_cpu_ms) {
  DrivenFrame d;
  d.index = index;
  d.frame_ns = frame_ns(index);
  d.gaze = gaze;
  d.gaze_cpu_ms = gaze_cpu_ms;
  d.times = pipeline().render(poses, {gaze.eye(core::Eye::Left).dir, gaze.eye(core::Eye::Right).dir}, index);
  return d;
}

}  // namespace fovea::pipeline
