// fovea view: the mirror window — what both panels of a display show, through the lens
// distortion pass on the GPU, with the gaze marker; `--gaze mouse` makes the mouse
// position on the window the gaze.
#include <chrono>
#include <iostream>
#include <optional>
#include <thread>

#include "command.hpp"
#include "fovea/compositor/distortion.hpp"
#include "fovea/compositor/mirror_window.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/hidden_area.hpp"
#include "fovea/core/image.hpp"
#include "fovea/gpu/context.hpp"
#include "gaze_arg.hpp"

namespace fovea::tools {
namespace {

constexpr const char* kHelp = R"(usage: fovea view [options]

Opens the mirror window (X11; e.g. under Xvfb with DISPLAY set): both eyes' panels side
by side as the headset shows them, through the lens distortion pass, with a gaze marker.
Until the path tracer and reconstruction feed it, each eye shows a grid of view
directions (lines every 5 degrees) as the resolved image.

  --display NAME|FILE   display preset (fove0, vive, modern, small, tiny) or JSON file [small]
  --scene S             scene to path-trace (needs the renderer; not available yet)
  --gaze mouse|X,Y      mouse: the cursor over a panel is the gaze (looked at through the
                        lens); X,Y: fixed gaze in normalised view coordinates [0.5,0.5]
  --gaze-dir x,y,z      fixed gaze as a view-space direction (OpenXR: -Z forward, +Y up)
  --window WxH          window size [fits both panels in 1280x720]
  --frames N            close after N frames; 0 = when the window is closed [0]
  --screenshot PNG      write the last frame the window showed
  --panels PREFIX       write PREFIX-left.png, PREFIX-right.png (display space, per eye)
                        and PREFIX-panel.png (both side by side)
  --help                this text

Exit status: 0 on success, 1 when no window can be opened, 2 on invalid arguments.
)";

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
      std::cout << kHelp;
      return 0;
    }
  const Args args(argv, {"display", "scene", "gaze", "gaze-dir", "window", "frames", "screenshot", "panels"}, {});
  if (args.has("scene"))
    throw core::InputError("--scene needs the path tracer and the reconstruction, which this build does not "
                           "have yet; run without --scene to see the lens on a direction grid");
  const core::DisplayPreset d = core::load_display(args.str("display", "small"));
  const long frames = args.integer("frames", 0);
  if (frames < 0) throw core::InputError("option --frames: must be 0 or more");
  const bool mouse = args.str("gaze", "") == "mouse";
  const core::Lens lenses[2] = {core::Lens::for_eye(d, core::Eye::Left), core::Lens::for_eye(d, core::Eye::Right)};
  std::optional<glm::dvec3> fixed_gaze;
  if (!mouse) fixed_gaze = parse_gaze(args, lenses[0].view());

  // The resolved images are static for now: distort once on the GPU.
  gpu::Context ctx;
  compositor::PanelImage panels[2];
  for (int e = 0; e < 2; ++e) {
    const core::HiddenAreaMask mask(lenses[e]);
    compositor::DistortionPass pass(ctx, mask);
    panels[e] = pass.run(compositor::direction_grid(lenses[e].view()));
  }
  if (auto prefix = args.opt("panels")) write_panels(*prefix, panels);

  const double fit = std::min({1.0, 1280.0 / (2 * d.width), 720.0 / d.height});
  const auto [ww, wh] = args.has("window") ? parse_size(args.str("window", ""))
                                           : std::pair<int, int>{std::max(16, int(2 * d.width * fit)),
                                                                 std::max(16, int(d.height * fit))};
  compositor::MirrorWindow window(ww, wh, "fovea view: " + d.name);
  for (long frame = 0; frames == 0 || frame < frames; ++frame) {
    if (!window.poll()) break;
    std::optional<glm::dvec3> gaze = fixed_gaze;
    if (mouse)
      if (const auto p = window.cursor()) gaze = compositor::gaze_direction(lenses[int(p->eye)], p->uv);
    std::optional<glm::dvec2> marker[2];
    if (gaze)
      for (int e = 0; e < 2; ++e) marker[e] = compositor::gaze_panel_uv(lenses[e], *gaze);
    window.show(panels[0], panels[1], marker[0], marker[1]);
    std::this_thread::sleep_for(std::chrono::microseconds(long(1e6 / d.refresh_hz)));
  }
  if (auto shot = args.opt("screenshot")) core::write_png(*shot, window.screenshot().to_image());
  return 0;
}

}  // namespace

FOVEA_COMMAND(view_command, "view", "mirror window: both panels through the lens, gaze marker, mouse gaze", run);

}  // namespace fovea::tools
