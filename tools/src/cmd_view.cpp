// fovea view: the mirror window — what both panels of a display show, through the lens
// distortion pass on the GPU, with the gaze marker. With --scene each frame is path traced
// foveated at the current gaze (FramePipeline) and distorted; `--gaze mouse` makes the
// mouse position on the window the gaze.
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include "command.hpp"
#include "render_setup.hpp"
#include "fovea/compositor/distortion.hpp"
#include "fovea/compositor/mirror_window.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/core/image.hpp"
#include "fovea/devices/foveation_gaze.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/trace_choice.hpp"
#include "fovea/renderer/reference.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gaze_arg.hpp"

namespace fovea::tools::cmd_view {
namespace {

constexpr const char* kHelpHead = R"(usage: fovea view [options]

Opens the mirror window (X11; e.g. under Xvfb with DISPLAY set): both eyes' panels side
by side as the headset shows them, through the lens distortion pass, with a gaze marker.
With --scene every frame is path traced foveated at the current gaze (grid generation,
path tracing, reconstruction, resolve; as fovea render, skipping the lens' hidden area),
tone-mapped (ACES fit) and distorted for the panels. Without --scene each eye shows a grid
of view directions (lines every 5 degrees), a picture of the optics.

  --display NAME|FILE   display preset (fove0, vive, modern, wide, small, tiny) or JSON file [small]
  --scene S             cornell | furnace | glossy-spheres | stereo-occluders | default, or a
                        .gltf/.glb/.obj file: path trace it (otherwise the direction grid)
  --gaze G              mouse: the cursor over a panel is the gaze (looked at through that
                        eye's lens; kept when the cursor leaves the panels);
                        X,Y: fixed gaze in normalised view coordinates;
                        FILE or synthetic:SEED[?...]: a recording or synthetic gaze
                        (docs/gaze.md), sampled at frame / refresh rate [0.5,0.5]
  --gaze-dir x,y,z      fixed gaze as a view-space direction (OpenXR: -Z forward, +Y up)
)";
constexpr const char* kHelpTail = R"(  --optics direct|lut   distortion pass: evaluate the optics per pixel, or read them from
                        the 128x128 LUT cache [direct]
  --window WxH          window size [fits both panels in 1280x720]
  --frames N            close after N frames; 0 = when the window is closed [0]
  --screenshot PNG      write the last frame the window showed
  --panels PREFIX       write PREFIX-left.png, PREFIX-right.png (display space, per eye)
                        and PREFIX-panel.png (both side by side), of the last frame
  --help                this text

Exit status: 0 on success, 1 when no window can be opened, 2 on invalid arguments.
)";

// "X,Y": two numbers, the fixed gaze; anything else that is not "mouse" names a source.
bool is_point(const std::string& s) {
  const auto comma = s.find(',');
  if (comma == std::string::npos || s.find(',', comma + 1) != std::string::npos) return false;
  for (const std::string& part : {s.substr(0, comma), s.substr(comma + 1)}) {
    char* end = nullptr;
    std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0') return false;
  }
  return true;
}

compositor::OpticsEval parse_optics(const std::string& s) {
  if (s == "direct") return compositor::OpticsEval::Direct;
  if (s == "lut") return compositor::OpticsEval::Lut;
  throw core::InputError("option --optics: expected direct or lut, got \"" + s + "\"");
}

// What draws the resolved view images: the foveated pipeline on a scene.
std::pair<int, int> parse_size(const std::string& s) {
  const auto x = s.find('x');
  try {
    if (x != std::string::npos) {
      size_t a = 0, b = 0;
      const int w = std::stoi(s.substr(0, x), &a), h = std::stoi(s.substr(x + 1), &b);
      if (a == x && b == s.size() - x - 1 && w >= 16 && h >= 16 && w <= 16384 && h <= 16384) return {w, h};
    }
  } catch (const std::exception&) {
  }
  throw core::InputError("option --window: expected WxH within 16..16384, got \"" + s + "\"");
}

void write_panels(const std::string& prefix, const compositor::PanelImage (&p)[2]) {
  core::Image both(2 * p[0].width, p[0].height);
  for (int e = 0; e < 2; ++e) {
    const core::Image img = p[e].to_image();
    core::write_png(prefix + (e == 0 ? "-left.png" : "-right.png"), img);
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) both.at(e * img.width + x, y) = img.at(x, y);
  }
  core::write_png(prefix + "-panel.png", both);
}

int run(std::vector<std::string> argv) {
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") {
      std::cout << kHelpHead << frame_options_help() << kHelpTail;
      return 0;
    }
  const Args args(argv,
                  {"display", "scene", "trace", "gaze", "gaze-dir", "budget", "cap", "jitter", "optics", "window", "frames",
                   "distribution", "denoiser", "bmfr-precision", "stereo-share", "bounces", "seed", "landing-spp",
                   "pixel-albedo", "lattice-blur", "raster-filter", "screenshot", "panels"},
                  {});
  const core::DisplayPreset d = core::load_display(args.str("display", core::kDefaultDisplay));
  const long frames = args.integer("frames", 0);
  if (frames < 0) throw core::InputError("option --frames: must be 0 or more");
  const compositor::OpticsEval eval = parse_optics(args.str("optics", "direct"));
  // The frame of `fovea render`: the same defaults and option names (pipeline/frame_config.hpp).
  const pipeline::FrameConfig frame = frame_config_of(args);
  const core::EyeOptics optics[2] = {core::EyeOptics(d, core::Eye::Left), core::EyeOptics(d, core::Eye::Right)};

  // The gaze: the mouse, a fixed direction, or a gaze source (recording, synthetic).
  const std::string gaze_arg = args.str("gaze", "");
  const bool mouse = gaze_arg == "mouse";
  std::unique_ptr<devices::FoveationGaze> source;
  std::array<glm::dvec3, 2> gaze{glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)};
  if (!mouse && !gaze_arg.empty() && !args.has("gaze-dir") && !is_point(gaze_arg)) {
    devices::SourceOptions so;
    so.display = d;
    source = std::make_unique<devices::FoveationGaze>(gaze_arg, so);
  } else if (!mouse) {
    gaze[0] = gaze[1] = parse_gaze(args, optics[0].view());
  } else if (args.has("gaze-dir")) {
    throw core::InputError("give either --gaze or --gaze-dir, not both");
  }

  // Inputs are checked (the scene loaded) before the window opens, the window before the
  // GPU work: without an X display there is no point building the renderer.
  std::optional<renderer::Scene> scene;
  if (auto name = args.opt("scene")) {
    scene = renderer::load_scene(*name);
    for (const auto& w : scene->warnings) std::cerr << "warning: " << w << "\n";
  }
  const double fit = std::min({1.0, 1280.0 / (2 * d.width), 720.0 / d.height});
  const auto [ww, wh] = args.has("window") ? parse_size(args.str("window", ""))
                                           : std::pair<int, int>{std::max(16, int(2 * d.width * fit)),
                                                                 std::max(16, int(d.height * fit))};
  compositor::MirrorWindow window(ww, wh, "fovea view: " + d.name);

  gpu::Context ctx;
  std::array<std::unique_ptr<compositor::DistortionPass>, 2> passes;
  for (int e = 0; e < 2; ++e)
    passes[size_t(e)] = std::make_unique<compositor::DistortionPass>(ctx, optics[e].hidden(),
                                                                      compositor::ChannelSelect::All, eval);
  compositor::PanelImage panels[2];
  // A static head at the scene's camera, each eye's lens hidden area skipped.
  std::optional<pipeline::FrameDriver> driver;
  if (scene) {
    driver.emplace(ctx, *scene, d, pipeline::FrameDriverOptions{frame, true});
    if (source) driver->set_gaze(std::move(source));  // frames read it at their time
    std::cerr << "fovea view: frame " << to_json(frame).dump() << "\n";
    std::cerr << "fovea view: tracing " << renderer::tracing_name(driver->trace_choice().tracing) << ": "
              << driver->trace_choice().why << "\n";
  } else {
    // The direction grid is static: distort it once.
    for (int e = 0; e < 2; ++e) panels[e] = passes[size_t(e)]->run(compositor::direction_grid(optics[e].view()));
  }

  const auto period = std::chrono::microseconds(long(1e6 / d.refresh_hz));
  for (long frame = 0; frames == 0 || frame < frames; ++frame) {
    const auto frame_start = std::chrono::steady_clock::now();
    if (!window.poll()) break;
    if (mouse) {
      // Both eyes look along the direction seen through the lens under the cursor
      // (parallel eyes: vergence is ignored); off the panels the last gaze holds.
      if (const auto p = window.cursor()) gaze[0] = gaze[1] = core::gaze_direction(optics[int(p->eye)].lens(), p->uv);
    } else if (source) {  // no scene: the gaze for the marker only
      const devices::FoveaGaze g = source->at_frame_time(pipeline::frame_time_ns(std::uint32_t(frame), d.refresh_hz));
      for (int e = 0; e < 2; ++e) gaze[size_t(e)] = g.eye(core::Eye(e)).dir;
    }
    if (driver) {
      devices::FoveaGaze given;  // the mouse's or the fixed direction
      given.left.dir = given.combined.dir = gaze[0];
      given.right.dir = gaze[1];
      const pipeline::DrivenFrame f =
          driver->gaze() ? driver->step(std::uint32_t(frame)) : driver->step(std::uint32_t(frame), given, driver->static_poses());
      for (int e = 0; e < 2; ++e) gaze[size_t(e)] = f.gaze.eye(core::Eye(e)).dir;
      for (int e = 0; e < 2; ++e)
        panels[e] = passes[size_t(e)]->run(renderer::tone_map(driver->pipeline().image(core::Eye(e))));
    }
    std::optional<glm::dvec2> marker[2];
    for (int e = 0; e < 2; ++e) marker[e] = core::gaze_panel_uv(optics[e].lens(), gaze[size_t(e)]);
    window.show(panels[0], panels[1], marker[0], marker[1]);
    std::this_thread::sleep_until(frame_start + period);
  }
  // (A window closed before the first frame leaves no scene panels to write.)
  if (auto prefix = args.opt("panels"); prefix && panels[0].width > 0) write_panels(*prefix, panels);
  if (auto shot = args.opt("screenshot")) core::write_png(*shot, window.screenshot().to_image());
  return 0;
}

}  // namespace

FOVEA_COMMAND(view_command, "view", "mirror window: foveated path tracing of a scene through the lens, gaze marker, mouse gaze", run);

}  // namespace fovea::tools::cmd_view
