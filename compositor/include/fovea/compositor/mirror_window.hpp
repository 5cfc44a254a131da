#pragma once
// The mirror window: a desktop window (GLFW on X11; runs under Xvfb) showing what both
// panels show, side by side and letterboxed, with a gaze marker per eye. The mouse
// position over a panel is exposed as a gaze (which eye, panel position), the `mouse`
// gaze source for interactive use.
#include <memory>
#include <optional>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "fovea/compositor/distortion.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/lens.hpp"

namespace fovea::compositor {

struct PanelPoint {
  core::Eye eye = core::Eye::Left;
  glm::dvec2 uv{0.5, 0.5};  // panel position in [0,1]², x right, y down
};

class MirrorWindow {
 public:
  // Opens the window (client area width × height). Throws std::runtime_error naming the
  // cause when no X display is reachable or GLFW/OpenGL fail.
  MirrorWindow(int width, int height, const std::string& title);
  ~MirrorWindow();
  MirrorWindow(const MirrorWindow&) = delete;
  MirrorWindow& operator=(const MirrorWindow&) = delete;

  // Draws both panels (equal sizes) with a marker at each given panel point and presents.
  void show(const PanelImage& left, const PanelImage& right, std::optional<glm::dvec2> gaze_left_uv,
            std::optional<glm::dvec2> gaze_right_uv);
  // Handles window events; false once the window was asked to close.
  bool poll();
  // The cursor as a gaze: the panel under it and the position there; nullopt when it is
  // outside both panels (or outside the window).
  std::optional<PanelPoint> cursor() const;
  // The last presented frame as drawn (read back before presenting), RGBA8, top row first.
  PanelImage screenshot() const;

  int width() const { return width_; }
  int height() const { return height_; }
  // X11 handles (Display*, Window) for tests that talk to the X server directly.
  void* x11_display() const;
  unsigned long x11_window() const;

 private:
  // Where the two panels sit in the window (pixels, origin top-left).
  struct Layout {
    double x0 = 0, y0 = 0, panel_w = 1, panel_h = 1;
  };
  Layout layout_{};
  int width_, height_;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fovea::compositor
