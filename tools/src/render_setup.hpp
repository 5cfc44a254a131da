#pragma once
// The scene on the Vulkan device and the stereo foveated pipeline over it, as `fovea render`
// and `fovea latency` set them up: a static head at the scene's camera, the display's views,
// and (when culling) each eye's lens hidden area skipped.
#include <array>

#include "fovea/core/display.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/gpu/context.hpp"
#include "command.hpp"
#include "fovea/pipeline/frame_config.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/scene.hpp"
#include "fovea/renderer/trace_choice.hpp"

namespace fovea::tools {

// The frame options given on the command line (--budget, --distribution, --jitter, --denoiser,
// --bmfr-precision, --stereo-share, --trace, --bounces: pipeline::frame_option_names) over
// pipeline::FrameConfig's defaults, finished (Cartesian's budget, validated). `not_frame`:
// names a command uses for something else (fovea latency's --jitter is the tracker's).
pipeline::FrameConfig frame_config_of(const Args& args, const std::vector<std::string>& not_frame = {});

// A frame (FrameConfig) and whether the lens' hidden area is skipped.
struct RenderSetupOptions {
  pipeline::FrameConfig frame;
  bool cull = true;
};

// Members in construction order; they refer to each other, so the setup stays in place.
struct RenderSetup {
  RenderSetup(const renderer::Scene& scene, const core::DisplayPreset& display, const RenderSetupOptions& options);
  RenderSetup(const RenderSetup&) = delete;
  RenderSetup& operator=(const RenderSetup&) = delete;

  gpu::Context ctx;
  renderer::TraceChoice trace_choice;  // --trace auto resolved for this device (renderer/trace_choice.hpp)
  renderer::GpuScene gpu_scene;
  core::StereoViews views;
  std::array<core::Pose, 2> poses;  // the static head's eyes
  pipeline::FramePipeline pipeline;
};

}  // namespace fovea::tools
