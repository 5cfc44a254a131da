#pragma once
// The frame options of the command line, and the device with the frame driver over it.
#include <string>
#include <vector>

#include "fovea/core/display.hpp"
#include "fovea/gpu/context.hpp"
#include "command.hpp"
#include "fovea/pipeline/frame_config.hpp"
#include "fovea/pipeline/frame_driver.hpp"
#include "fovea/renderer/scene.hpp"

namespace fovea::tools {

// The frame options given on the command line (--budget, --distribution, --jitter, --denoiser,
// --bmfr-precision, --stereo-share, --trace, --bounces: pipeline::frame_option_names) over
// pipeline::FrameConfig's defaults, finished (Cartesian's budget, validated). `not_frame`:
// names a command uses for something else (fovea latency's --jitter is the tracker's).
pipeline::FrameConfig frame_config_of(const Args& args, const std::vector<std::string>& not_frame = {});

// The frame options' lines of a command's --help, the same in every command that takes them
// (`fovea render`, `latency`, `view`; the layer's configuration has the same names): every
// name of pipeline::frame_option_names but those in `not_frame`, each with the default
// pipeline::FrameConfig has.
std::string frame_options_help(const std::vector<std::string>& not_frame = {});

// The device and the frame driver on it (pipeline/frame_driver.hpp), as `fovea render` and
// `fovea latency` set them up: the display preset's views with a static head at the scene's
// camera, each eye's lens hidden area skipped unless `cull` is off.
struct RenderSetup {
  RenderSetup(const renderer::Scene& scene, const core::DisplayPreset& display, const pipeline::FrameConfig& frame,
              bool cull = true)
      : driver(ctx, scene, display, {frame, cull}) {}
  RenderSetup(const RenderSetup&) = delete;
  RenderSetup& operator=(const RenderSetup&) = delete;

  gpu::Context ctx;
  pipeline::FrameDriver driver;
};

}  // namespace fovea::tools
