#pragma once
// The one way every entry point — `fovea render`, `view`, `latency` and the OpenXR layer — sets
// a scene up for foveated frames: the traversal that FrameConfig's `--trace` resolves to on the
// device, the scene on the device with it, and the stereo FramePipeline with the frame
// configuration, its light transport resolved for the scene. The command-line tools render
// the display preset's views with a static head at the scene's camera and skip each eye's lens
// hidden area; the layer renders the views the application submits, its eye poses placed at
// the scene's camera, and sets the runtime's hidden area itself.
// Each frame is one step(): the gaze read for it, the pipeline's frame, and its times by the
// names every timing record uses.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fovea/core/display.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/devices/foveation_gaze.hpp"
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

// Frame `index`'s time on a display's frame timeline: index / refresh rate, from 0.
core::TimeNs frame_time_ns(std::uint32_t index, double refresh_hz);

// One frame through the driver.
struct DrivenFrame {
  std::uint32_t index = 0;
  core::TimeNs frame_ns = 0;  // the frame's time on the frame timeline (index / refresh rate)
  devices::FoveaGaze gaze;    // read for the frame (the eyes' directions and the sample's times)
  FrameTimes times;           // the pipeline's: stages, submission, what each eye's grid did with its gaze
  double gaze_cpu_ms = 0;     // reading the gaze (CPU, monotonic clock; 0 when read elsewhere)
  // The frame's times by the names every timing record uses (FrameTimes::gpu_record, cpu_record).
  std::vector<std::pair<std::string, double>> gpu_ms() const { return times.gpu_record(); }
  std::vector<std::pair<std::string, double>> cpu_ms() const { return times.cpu_record(gaze_cpu_ms); }
};

class FrameDriver {
 public:
  // The display preset's views (core::stereo_views) with the head at the scene's camera.
  FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::DisplayPreset& display,
              const FrameDriverOptions& options);
  // Given views (the application's, in the layer) and each one's hidden area where it is
  // known (the grids laid out for the pixels it leaves); a later one through set_visibility.
  FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::StereoViews& views,
              const FrameDriverOptions& options, const EyeMasks& visibility = {});
  FrameDriver(const FrameDriver&) = delete;
  FrameDriver& operator=(const FrameDriver&) = delete;

  const FrameConfig& frame() const { return frame_; }
  const renderer::TraceChoice& trace_choice() const { return trace_choice_; }
  const renderer::GpuScene& gpu_scene() const { return gpu_scene_; }
  const core::StereoViews& views() const { return views_; }
  // The eyes of the static head at the scene's camera (the views' poses).
  std::array<core::Pose, 2> static_poses() const { return views_.poses(); }
  FramePipeline& pipeline() { return pipeline_.value(); }
  const FramePipeline& pipeline() const { return pipeline_.value(); }

  // Each eye's hidden area from the next frame on, the grids laid out again for the pixels it
  // leaves: a new pipeline (pipeline() refers to it; the history starts over). For a hidden
  // area that changes during a session (the layer, after the runtime's change event). Where
  // making it throws, the driver is left without one (pipeline() throws).
  void set_visibility(const EyeMasks& visibility);

  // The display depth (FramePipeline::enable_depth_output) from the next frame on, in this
  // pipeline and every one set_visibility makes: for depth compositing (the layer, once the
  // application submits depth), which nothing else reads.
  void enable_depth_output();
  bool depth_output() const { return depth_output_; }

  // An eye pose given in the scene camera's frame (the application's reference space, its
  // origin at the camera) in world coordinates.
  core::Pose at_camera(const core::Pose& eye) const;

  // The gaze source frames read (`fovea render`, `view`): frame i at its time on the frame
  // timeline, i / the display preset's refresh rate from 0 (a live source: the host clock
  // now). Display-preset drivers only.
  void set_gaze(std::unique_ptr<devices::FoveationGaze> gaze);
  const devices::FoveationGaze* gaze() const { return gaze_.get(); }
  // Frame `index`'s time on the display preset's frame timeline (0 for given views).
  core::TimeNs frame_ns(std::uint32_t index) const { return refresh_hz_ > 0 ? frame_time_ns(index, refresh_hz_) : 0; }

  // One frame with the static head: the gaze read from set_gaze's source.
  DrivenFrame step(std::uint32_t index);
  // One frame with a gaze read elsewhere (the layer: the eye-gaze action or its source at the
  // display time; `fovea latency`: the tracker model at the frame's wake; `fovea view`: the
  // mouse) at the given eye poses, `gaze_cpu_ms` what reading it took.
  DrivenFrame step(std::uint32_t index, const devices::FoveaGaze& gaze, const std::array<core::Pose, 2>& poses,
                   double gaze_cpu_ms = 0);

 private:
  FrameDriver(gpu::Context& ctx, const renderer::Scene& scene, const core::StereoViews& views,
              const FrameDriverOptions& options, const std::optional<core::DisplayPreset>& display,
              const EyeMasks& visibility);

  gpu::Context& ctx_;
  FrameConfig frame_;
  bool depth_output_ = false;
  double refresh_hz_ = 0;  // the display preset's (0: given views)
  std::unique_ptr<devices::FoveationGaze> gaze_;
  core::Pose camera_;
  renderer::TraceChoice trace_choice_;
  renderer::GpuScene gpu_scene_;
  core::StereoViews views_;
  core::DistributionParams distribution_;  // frame_'s, named for the display preset
  renderer::PathConfig path_;              // frame_'s transport, resolved for the scene
  std::optional<FramePipeline> pipeline_;
};

}  // namespace fovea::pipeline
