#include "fovea/compositor/mirror_window.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "fovea/core/display.hpp"
#include "fovea/core/hidden_area.hpp"
#include "gpu_fixture.hpp"
#include "xvfb.hpp"

// Xlib last: its None/Bool/Status macros clash with GoogleTest's names.
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#undef None
#undef Bool
#undef Status

using namespace fovea;

namespace {

using fovea::test::Xvfb;

compositor::PanelImage solid(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  compositor::PanelImage p{w, h, std::vector<std::uint8_t>(size_t(w) * h * 4)};
  for (size_t i = 0; i < p.rgba.size(); i += 4) p.rgba[i] = r, p.rgba[i + 1] = g, p.rgba[i + 2] = b, p.rgba[i + 3] = 255;
  return p;
}

// The window's pixels as the X server has them.
compositor::PanelImage x_screenshot(const compositor::MirrorWindow& w) {
  Display* dpy = static_cast<Display*>(w.x11_display());
  XSync(dpy, False);
  XImage* img = XGetImage(dpy, w.x11_window(), 0, 0, unsigned(w.width()), unsigned(w.height()), AllPlanes, ZPixmap);
  compositor::PanelImage out{w.width(), w.height(), std::vector<std::uint8_t>(size_t(w.width()) * w.height() * 4)};
  if (!img) return out;
  for (int y = 0; y < w.height(); ++y)
    for (int x = 0; x < w.width(); ++x) {
      const unsigned long p = XGetPixel(img, x, y);
      std::uint8_t* o = &out.rgba[(size_t(y) * w.width() + x) * 4];
      o[0] = std::uint8_t((p & img->red_mask) >> 16);
      o[1] = std::uint8_t((p & img->green_mask) >> 8);
      o[2] = std::uint8_t(p & img->blue_mask);
      o[3] = 255;
    }
  XDestroyImage(img);
  return out;
}

const std::uint8_t* px(const compositor::PanelImage& img, int x, int y) {
  return &img.rgba[(size_t(y) * img.width + x) * 4];
}

#define REQUIRE_XVFB(x)                                                                       \
  if (!(x).running()) GTEST_SKIP() << "Xvfb is not installed (/usr/bin/Xvfb): the mirror "    \
                                      "window needs an X server; install the xvfb package"

}  // namespace

TEST(MirrorWindow, ShowsBothEyesAndTheGazeMarkers) {
  Xvfb x;
  REQUIRE_XVFB(x);
  // 640×400 window, two 64×72 panels: scale 5, panels at y 20..380, x 0..320 and 320..640.
  compositor::MirrorWindow w(640, 400, "fovea mirror test");
  w.show(solid(64, 72, 200, 30, 30), solid(64, 72, 30, 30, 200), glm::dvec2(0.25, 0.5), std::nullopt);
  w.poll();
  const compositor::PanelImage shot = x_screenshot(w);
  const compositor::PanelImage gl = w.screenshot();
  // What the X server shows is what was drawn.
  for (int y = 0; y < 400; y += 7)
    for (int x = 0; x < 640; x += 7)
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(px(shot, x, y)[c], px(gl, x, y)[c], 2) << x << "," << y;
  const auto expect_colour = [&](int x, int y, int r, int g, int b) {
    EXPECT_NEAR(px(shot, x, y)[0], r, 3) << x << "," << y;
    EXPECT_NEAR(px(shot, x, y)[1], g, 3) << x << "," << y;
    EXPECT_NEAR(px(shot, x, y)[2], b, 3) << x << "," << y;
  };
  expect_colour(240, 100, 200, 30, 30);  // left eye
  expect_colour(480, 300, 30, 30, 200);  // right eye
  expect_colour(320, 5, 26, 26, 26);     // letterbox
  // The left gaze marker around window (80, 200); none on the right panel.
  int green_left = 0, green_right = 0;
  for (int y = 160; y < 240; ++y)
    for (int x = 40; x < 120; ++x) {
      green_left += px(shot, x, y)[1] > 200 && px(shot, x, y)[0] < 100;
      green_right += px(shot, x + 320, y)[1] > 200 && px(shot, x + 320, y)[0] < 100;
    }
  EXPECT_GT(green_left, 50);
  EXPECT_EQ(green_right, 0);
}

TEST(MirrorWindow, CursorIsTheGaze) {
  Xvfb x;
  REQUIRE_XVFB(x);
  compositor::MirrorWindow w(640, 400, "fovea mirror test");
  w.show(solid(64, 72, 0, 0, 0), solid(64, 72, 0, 0, 0), std::nullopt, std::nullopt);
  Display* dpy = static_cast<Display*>(w.x11_display());
  const auto move = [&](int mx, int my) {
    XWarpPointer(dpy, 0L /* None */, w.x11_window(), 0, 0, 0, 0, mx, my);
    XSync(dpy, False);
    w.poll();
  };
  move(80, 200);
  auto p = w.cursor();
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->eye, core::Eye::Left);
  EXPECT_NEAR(p->uv.x, 0.25, 0.01);
  EXPECT_NEAR(p->uv.y, 0.5, 0.01);
  move(560, 110);
  p = w.cursor();
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->eye, core::Eye::Right);
  EXPECT_NEAR(p->uv.x, 0.75, 0.01);
  EXPECT_NEAR(p->uv.y, 0.25, 0.01);
  move(300, 5);  // letterbox: no gaze
  EXPECT_FALSE(w.cursor().has_value());
}

using MirrorGpu = fovea::test::GpuTest;

TEST_F(MirrorGpu, ShowsTheDistortedPanels) {
  Xvfb x;
  REQUIRE_XVFB(x);
  const core::DisplayPreset d = core::load_display("tiny");
  compositor::PanelImage panels[2];
  for (core::Eye eye : {core::Eye::Left, core::Eye::Right}) {
    const core::HiddenAreaMask mask(core::Lens::for_eye(d, eye));
    compositor::DistortionPass pass(ctx(), mask);
    panels[int(eye)] = pass.run(compositor::direction_grid(mask.lens().view()));
  }
  compositor::MirrorWindow w(2 * d.width, d.height, "fovea mirror test");  // scale 1: pixel exact
  w.show(panels[0], panels[1], std::nullopt, std::nullopt);
  const compositor::PanelImage shot = x_screenshot(w);
  for (int y = 0; y < d.height; ++y)
    for (int xx = 0; xx < 2 * d.width; ++xx) {
      const compositor::PanelImage& p = panels[xx < d.width ? 0 : 1];
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(px(shot, xx, y)[c], px(p, xx % d.width, y)[c], 2) << xx << "," << y;
    }
}
