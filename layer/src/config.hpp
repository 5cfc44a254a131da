#pragma once
// The layer's configuration for one application. Sources, later ones winning:
//   $XDG_CONFIG_HOME/fovea/layer.json (else ~/.config/fovea/layer.json):
//     {"default": {...}, "applications": {"<XrApplicationInfo::applicationName>": {...}}}
//     with keys "scene", "composite", "app_background", "gaze", "render", "compositor", "handover",
//     "render_priority" and the frame options of `fovea render` by their names ("budget",
//     "distribution", "jitter", "denoiser", "bmfr-precision", "stereo-share", "trace", "bounces":
//     pipeline/frame_config.hpp) (an application's section over "default");
//   env FOVEA_LAYER_SCENE, then FOVEA_SCENE (the scene); FOVEA_GAZE (the gaze source);
//   FOVEA_LAYER_RENDER (the render mode); FOVEA_LAYER_COMPOSITOR (where compositing runs);
//   FOVEA_LAYER_HANDOVER (how traced frames reach the application's device);
//   FOVEA_LAYER_RENDER_PRIORITY (the render thread's CPU priority); FOVEA_LAYER_<OPTION> for
//   each frame option (FOVEA_LAYER_BUDGET, FOVEA_LAYER_STEREO_SHARE, ...).
#include <array>
#include <optional>
#include <string>

#include "fovea/pipeline/frame_config.hpp"

namespace fovea::layer {

// How the application's pixels are combined with the path-traced scene.
enum class Composite {
  AppOnTop,   // the application's pixels wherever they differ from its background colour
  Alpha,      // the application's pixels over the scene by their alpha
  SceneOnly,  // the scene alone (comparisons)
};

// The render thread's CPU scheduling. Default nice 19: SCHED_IDLE starves the path tracer on
// a loaded host (no traced frame in 2500 frames at load 19 on two cores) and its threads can
// hold process-wide locks (the address space's, the allocator's) the application then waits for.
struct RenderPriority {
  bool idle = false;  // SCHED_IDLE; else SCHED_OTHER at `nice`
  int nice = 19;
};
std::string render_priority_name(const RenderPriority& p);

struct LayerConfig {
  std::string scene;  // renderer::load_scene name or path; empty: none (pass-through)
  Composite composite = Composite::AppOnTop;
  // AppOnTop's background colour (8-bit, as stored in the application's image); unset: the
  // most frequent colour on the image border, per frame.
  std::optional<std::array<int, 3>> app_background;
  std::string gaze;  // devices::open_gaze_source URI; empty: none (fixed foveation, gaze_input.hpp)
  std::string origin;  // where the scene setting came from, for the log
  // "render": "async" (false): xrEndFrame shows the newest frame the render thread finished;
  // "lockstep" (true): it waits for the frame traced for its own views (deterministic output
  // for captures and comparisons; the application runs at the path tracer's rate).
  bool lockstep = false;
  // "compositor": "gpu" (true): a compute pass on the application's device, the host path
  // when that device cannot run it; "host" (false): always the host round trip.
  bool gpu_compositor = true;
  // "handover": "shared" (true): the GPU composition's traced frames are written by the path
  // tracer, on the application's device or the layer's own, into memory it imports from the
  // application's device, when the runtime created that device through the layer
  // (XR_KHR_vulkan_enable2: the layer enables VK_KHR_external_memory_fd on it and adds the
  // path tracer's queue where it can); "host" (false): read back and written by the host.
  bool shared_handover = true;
  // "render_priority": a nice value 0..19 (SCHED_OTHER; default 19) or "idle" (SCHED_IDLE) for the render
  // thread and the threads of the device it creates (Linux threads inherit both), so that on a
  // CPU device the path tracer runs below the application's threads.
  RenderPriority render_priority;
  // The frame: the defaults and option names of `fovea render` (finished: validated).
  pipeline::FrameConfig frame;
  bool budget_given = false;  // for finish(): Cartesian refuses a budget other than 1
};

// Throws core::InputError naming the file and field for a malformed configuration file.
LayerConfig load_config(const std::string& application);
// Parses one configuration file's text (for tests and load_config).
LayerConfig parse_config(const std::string& text, const std::string& origin, const std::string& application);

const char* composite_name(Composite c);

}  // namespace fovea::layer
