#include "fovea/compositor/mirror_window.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#define GLFW_INCLUDE_NONE
#include <GL/gl.h>
#include <GLFW/glfw3.h>
#include <glm/geometric.hpp>

// GLFW's X11 accessors, declared here because glfw3native.h pulls in the Xrandr headers;
// Display* and Window (an XID) have the ABI of void* and unsigned long.
extern "C" void* glfwGetX11Display(void);
extern "C" unsigned long glfwGetX11Window(GLFWwindow* window);

namespace fovea::compositor {

namespace {

std::string glfw_error() {
  const char* what = nullptr;
  const int code = glfwGetError(&what);
  return code == GLFW_NO_ERROR ? std::string("unknown error") : std::string(what ? what : "error");
}

// A ring with a cross: visible on any content (dark outline, bright core).
void draw_marker(std::vector<std::uint8_t>& rgba, int stride_px, int x0, int w, int h, glm::dvec2 centre, int radius) {
  const auto put = [&](int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    if (x < 0 || y < 0 || x >= w || y >= h) return;
    std::uint8_t* p = &rgba[(size_t(y) * stride_px + x0 + x) * 4];
    p[0] = r, p[1] = g, p[2] = b, p[3] = 255;
  };
  for (int dy = -radius - 2; dy <= radius + 2; ++dy)
    for (int dx = -radius - 2; dx <= radius + 2; ++dx) {
      const double d = std::hypot(dx, dy);
      const int x = int(std::floor(centre.x)) + dx, y = int(std::floor(centre.y)) + dy;
      if (std::abs(d - radius) < 1.0 || ((dx == 0 || dy == 0) && d < radius * 0.5)) put(x, y, 40, 255, 60);
      else if (std::abs(d - radius) < 2.0) put(x, y, 0, 0, 0);
    }
}

}  // namespace

struct MirrorWindow::Impl {
  GLFWwindow* window = nullptr;
  GLuint texture = 0;
  PanelImage last_frame;
};

MirrorWindow::MirrorWindow(int width, int height, const std::string& title)
    : width_(width), height_(height), impl_(std::make_unique<Impl>()) {
  if (width < 16 || height < 16 || width > 16384 || height > 16384)
    throw std::runtime_error("mirror window: size must be within 16..16384 pixels");
#if GLFW_VERSION_MAJOR > 3 || (GLFW_VERSION_MAJOR == 3 && GLFW_VERSION_MINOR >= 4)
  glfwInitHint(GLFW_PLATFORM, GLFW_PLATFORM_X11);
#endif
  if (!glfwInit()) throw std::runtime_error("mirror window: cannot open an X display (" + glfw_error() + "); set DISPLAY, e.g. run Xvfb :99 and DISPLAY=:99");
  glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  impl_->window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!impl_->window) {
    const std::string why = glfw_error();
    glfwTerminate();
    throw std::runtime_error("mirror window: cannot create an OpenGL window (" + why + ")");
  }
  glfwMakeContextCurrent(impl_->window);
  glfwSwapInterval(0);  // the compositor paces itself; never block on a (virtual) vblank
  glGenTextures(1, &impl_->texture);
  glBindTexture(GL_TEXTURE_2D, impl_->texture);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP);
}

MirrorWindow::~MirrorWindow() {
  if (impl_->window) {
    glfwMakeContextCurrent(impl_->window);
    glDeleteTextures(1, &impl_->texture);
    glfwDestroyWindow(impl_->window);
  }
  glfwTerminate();
}

void MirrorWindow::show(const PanelImage& left, const PanelImage& right, std::optional<glm::dvec2> gaze_left,
                        std::optional<glm::dvec2> gaze_right) {
  if (left.width != right.width || left.height != right.height || left.width < 1 || left.height < 1)
    throw std::invalid_argument("mirror window: both panels need the same non-empty size");
  const int W = left.width, H = left.height;
  // Both panels side by side in one texture, markers drawn in.
  std::vector<std::uint8_t> rgba(size_t(2 * W) * H * 4);
  for (int y = 0; y < H; ++y) {
    std::copy_n(&left.rgba[size_t(y) * W * 4], W * 4, &rgba[size_t(y) * 2 * W * 4]);
    std::copy_n(&right.rgba[size_t(y) * W * 4], W * 4, &rgba[(size_t(y) * 2 * W + W) * 4]);
  }
  const int radius = std::max(4, std::min(W, H) / 40);
  if (gaze_left) draw_marker(rgba, 2 * W, 0, W, H, *gaze_left * glm::dvec2(W, H), radius);
  if (gaze_right) draw_marker(rgba, 2 * W, W, W, H, *gaze_right * glm::dvec2(W, H), radius);

  // Letterbox: the largest 2W:H rectangle that fits, centred.
  const double scale = std::min(double(width_) / (2 * W), double(height_) / H);
  layout_ = {(width_ - 2 * W * scale) / 2, (height_ - H * scale) / 2, W * scale, H * scale};

  glfwMakeContextCurrent(impl_->window);
  glViewport(0, 0, width_, height_);
  glClearColor(0.1f, 0.1f, 0.1f, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  glBindTexture(GL_TEXTURE_2D, impl_->texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 2 * W, H, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  glMatrixMode(GL_PROJECTION);
  glLoadIdentity();
  glOrtho(0, width_, height_, 0, -1, 1);  // window pixels, y down
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  glEnable(GL_TEXTURE_2D);
  const double x0 = layout_.x0, y0 = layout_.y0, x1 = x0 + 2 * layout_.panel_w, y1 = y0 + layout_.panel_h;
  glBegin(GL_QUADS);
  glTexCoord2d(0, 0), glVertex2d(x0, y0);
  glTexCoord2d(1, 0), glVertex2d(x1, y0);
  glTexCoord2d(1, 1), glVertex2d(x1, y1);
  glTexCoord2d(0, 1), glVertex2d(x0, y1);
  glEnd();
  glDisable(GL_TEXTURE_2D);
  // Keep the frame: after the swap the back buffer's contents are undefined.
  std::vector<std::uint8_t> bottom_up(size_t(width_) * height_ * 4);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
  PanelImage& frame = impl_->last_frame;
  frame = {width_, height_, std::vector<std::uint8_t>(bottom_up.size())};
  for (int y = 0; y < height_; ++y)
    std::copy_n(&bottom_up[size_t(height_ - 1 - y) * width_ * 4], width_ * 4, &frame.rgba[size_t(y) * width_ * 4]);
  glfwSwapBuffers(impl_->window);
  glFinish();
}

bool MirrorWindow::poll() {
  glfwPollEvents();
  return !glfwWindowShouldClose(impl_->window);
}

std::optional<PanelPoint> MirrorWindow::cursor() const {
  double x = 0, y = 0;
  glfwGetCursorPos(impl_->window, &x, &y);
  const double u = (x - layout_.x0) / layout_.panel_w, v = (y - layout_.y0) / layout_.panel_h;
  if (!(v >= 0 && v <= 1 && u >= 0 && u <= 2)) return std::nullopt;
  if (u <= 1) return PanelPoint{core::Eye::Left, {u, v}};
  return PanelPoint{core::Eye::Right, {u - 1, v}};
}

PanelImage MirrorWindow::screenshot() const { return impl_->last_frame; }

void* MirrorWindow::x11_display() const { return glfwGetX11Display(); }
unsigned long MirrorWindow::x11_window() const { return glfwGetX11Window(impl_->window); }

}  // namespace fovea::compositor
