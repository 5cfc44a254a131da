#pragma once
// The one way every entry point — `fovea render`, `view`, `latency` and the OpenXR layer — sets
// a scene up for foveated frames: the traversal that FrameConfig's `--trace` resolves to on the
// device, the scene on the device with it, and the stereo FramePipeline with the frame
// configuration, its light transport resolved for the scene. The command-line tools render
// the display preset's views with a static head at the scene's camera and skip each eye's lens
// hidden area; the layer renders the views the application submits, its eye poses placed at
// the scene's camera, and sets the runtime's hidden area itself.
#include <array>
#include <optional>

#include "fovea/core/display.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/pipeline/frame_config.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/scene.hpp"
#include "fovea/renderer/trace_choice.hpp"

namespace fovea::pipeline {

struct FrameDriverOptions {
  FrameConfig frame;
  // The display preset's lens hidden area is skipped (the preset's views only).
  bool cull = true;
  // `--trace auto` may measure both traversals (seconds at start-up; cached per device and
  // driver). false: the cached choice, or the static one (the layer's first frame waits for none).
  bool measure_trace = true;
};

class FrameDriver {
 public:
  // The display preset's views (core::stereo_views) with the head at the scene's camera.
  FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::DisplayPreset& display,
              const FrameDriverOptions& options);
  // Given views (the application's, in the layer): no hidden area until set_visibility.
  FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::StereoViews& views,
              const FrameDriverOptions& options);
  FrameDriver(const FrameDriver&) = delete;
  FrameDriver& operator=(const FrameDriver&) = delete;

  const FrameConfig& frame() const { return frame_; }
  const renderer::TraceChoice& trace_choice() const { return trace_choice_; }
  const renderer::GpuScene& gpu_scene() const { return gpu_scene_; }
  const core::StereoViews& views() const { return views_; }
  // The eyes of the static head at the scene's camera (the views' poses).
  std::array<core::Pose, 2> static_poses() const { return views_.poses(); }
  FramePipeline& pipeline() { return pipeline_; }
  const FramePipeline& pipeline() const { return pipeline_; }

  // An eye pose given in the scene camera's frame (the application's reference space, its
  // origin at the camera) in world coordinates.
  core::Pose at_camera(const core::Pose& eye) const;

 private:
  FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::StereoViews& views,
              const FrameDriverOptions& options, const std::optional<core::DisplayPreset>& display);

  FrameConfig frame_;
  core::Pose camera_;
  renderer::TraceChoice trace_choice_;
  renderer::GpuScene gpu_scene_;
  core::StereoViews views_;
  FramePipeline pipeline_;
};

}  // namespace fovea::pipeline
