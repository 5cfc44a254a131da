#include "fovea/renderer/display_albedo.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"
#include "fovea/shaders/pt_primary.h"
#include "fovea/shaders/pt_trace.h"
#include "tracer_pipeline.hpp"

namespace fovea::renderer {

namespace {
constexpr double kDeg = std::numbers::pi / 180;
constexpr int kConeSteps = 64;  // directions around the cone's rim

std::vector<gpu::Binding> bindings() {
  std::vector<gpu::Binding> b(PRIMARY_BINDING_COUNT, gpu::Binding::TexelBuffer);
  b[PRIMARY_BINDING_TEX_TABLE] = gpu::Binding::StorageBuffer;
  b[PRIMARY_BINDING_OUT] = gpu::Binding::StorageBuffer;
  return b;
}
}  // namespace

PixelWindow cone_window(const core::View& view, glm::dvec3 axis, double radius_deg, std::uint32_t max_pixels) {
  const double len = glm::length(axis);
  if (!std::isfinite(len) || !(len > 0) || !(radius_deg > 0) || max_pixels == 0) return {};
  const glm::dvec3 a = axis / len;
  const double w = view.width(), h = view.height();
  const glm::dvec3 u =
      glm::normalize(glm::cross(a, std::abs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
  const glm::dvec3 v = glm::cross(a, u);
  const double r = std::min(radius_deg, 89.0) * kDeg;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double x0 = kInf, y0 = kInf, x1 = -kInf, y1 = -kInf;
  bool behind = false;
  for (int k = 0; k < kConeSteps; ++k) {
    const double phi = 2 * std::numbers::pi * k / kConeSteps;
    const glm::dvec3 d = std::cos(r) * a + std::sin(r) * (std::cos(phi) * u + std::sin(phi) * v);
    const std::optional<glm::dvec2> px = view.dir_to_pixel(d);  // none behind the eye's plane
    if (!px) { behind = true; continue; }
    x0 = std::min(x0, px->x), x1 = std::max(x1, px->x), y0 = std::min(y0, px->y), y1 = std::max(y1, px->y);
  }
  const std::optional<glm::dvec2> axis_px = view.dir_to_pixel(a);
  const bool front = axis_px.has_value();
  const glm::dvec2 centre = axis_px.value_or(glm::dvec2(0.0));
  if (behind) {  // the cone reaches the eye's plane: its trace runs off to infinity beyond the axis
    if (!front) return {};
    x0 = std::min(x0, centre.x), x1 = std::max(x1, centre.x), y0 = std::min(y0, centre.y), y1 = std::max(y1, centre.y);
    if (a.x > 0) x1 = kInf; else x0 = -kInf;
    if (a.y < 0) y1 = kInf; else y0 = -kInf;
  }
  if (!(x1 >= 0 && x0 <= w && y1 >= 0 && y0 <= h)) return {};  // off the raster (or no rim in front)
  // The rim's chords cut inside the curve by at most 1 − cos(π/64) of the box: one pixel more.
  const auto lo = [](double x, double n) { return std::uint32_t(std::clamp(std::floor(x) - 1, 0.0, n)); };
  const auto hi = [](double x, double n) { return std::uint32_t(std::clamp(std::ceil(x) + 1, 0.0, n)); };
  PixelWindow win{lo(x0, w), lo(y0, h), 0, 0};
  win.width = hi(x1, w) > win.x0 ? hi(x1, w) - win.x0 : 0;
  win.height = hi(y1, h) > win.y0 ? hi(y1, h) - win.y0 : 0;
  if (win.empty() || std::uint64_t(win.width) * win.height <= max_pixels) return win;
  // Cropped around the axis' pixel (or the box's centre), keeping the box's aspect.
  const glm::dvec2 c = front ? centre : glm::dvec2(win.x0 + 0.5 * win.width, win.y0 + 0.5 * win.height);
  const double scale = std::sqrt(double(max_pixels) / (double(win.width) * win.height));
  const std::uint32_t cw = std::clamp(std::uint32_t(win.width * scale), 1u, win.width);
  const std::uint32_t ch = std::clamp(std::uint32_t(win.height * scale), 1u, std::max(1u, max_pixels / cw));
  const auto place = [](double c, std::uint32_t size, std::uint32_t lo, std::uint32_t n) {
    return std::uint32_t(std::clamp(c - 0.5 * size, double(lo), double(lo + n - size)));
  };
  return {place(c.x, cw, win.x0, win.width), place(c.y, ch, win.y0, win.height), cw, ch};
}

std::uint32_t cone_window_capacity(const core::View& view, double radius_deg) {
  std::uint64_t most = 0;
  for (const double off : {0.0, 30.0, 60.0})
    for (const double phi : {0.0, 45.0, 90.0, 135.0, 180.0, 225.0, 270.0, 315.0}) {
      const glm::dvec3 d(std::sin(off * kDeg) * std::cos(phi * kDeg), std::sin(off * kDeg) * std::sin(phi * kDeg),
                         -std::cos(off * kDeg));
      most = std::max<std::uint64_t>(most, cone_window(view, d, radius_deg, 0xFFFFFFFFu).pixels());
    }
  return std::uint32_t(std::max<std::uint64_t>(most, 1));
}

DisplayAlbedo::DisplayAlbedo(gpu::Context& ctx, const GpuScene& scene)
    : ctx_(ctx),
      scene_(scene),
      pipeline_(ctx, tracer_pipeline(scene, "pt_primary", bindings(), sizeof(shaders::PtPrimaryParams),
                                     {gpu::SpecConstant::boolean(shaders::kPtSpecTextures,
                                                                 scene.features().textures)})) {}

PrimaryHits DisplayAlbedo::bind(std::uint32_t capacity) const {
  if (capacity == 0) throw core::InputError("display albedo: a window of no pixels");
  PrimaryHits o;
  o.capacity_ = capacity;
  o.hits_ = gpu::Buffer(ctx_, {VkDeviceSize(capacity) * 16, gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal,
                               "pt.primary_hits", VK_FORMAT_R32G32B32A32_SFLOAT});
  o.set_ = gpu::DescriptorSet(ctx_, pipeline_.set_layout(0));
  o.set_.bind(PT_BINDING_NODES, scene_.nodes()).bind(PT_BINDING_TRIS, scene_.triangles());
  o.set_.bind(PRIMARY_BINDING_SHADING, scene_.shading()).bind(PRIMARY_BINDING_MATERIALS, scene_.materials());
  o.set_.bind(PRIMARY_BINDING_TEX_TABLE, scene_.texture_table()).bind(PRIMARY_BINDING_TEXELS, scene_.texels());
  o.set_.bind(PRIMARY_BINDING_OUT, o.hits_);
  return o;
}

void DisplayAlbedo::record(VkCommandBuffer cmd, PrimaryHits& out, const core::View& view, const PixelWindow& window,
                           std::uint32_t grid, double texture_cone) const {
  if (window.empty()) return;
  if (window.x0 + window.width > std::uint32_t(view.width()) ||
      window.y0 + window.height > std::uint32_t(view.height()) || window.pixels() > out.capacity_)
    throw core::InputError("display albedo: window " + std::to_string(window.width) + "x" +
                           std::to_string(window.height) + " at (" + std::to_string(window.x0) + ", " +
                           std::to_string(window.y0) + ") outside the raster or beyond the buffer's " +
                           std::to_string(out.capacity_) + " pixels");
  shaders::PtPrimaryParams p{};
  set_eye_pose(p, view, "display albedo");
  p.tan_left = float(view.tan_left());
  p.tan_up = float(view.tan_up());
  p.pixel_tx = float((view.tan_right() - view.tan_left()) / view.width());
  p.pixel_ty = float((view.tan_up() - view.tan_down()) / view.height());
  p.x0 = window.x0;
  p.y0 = window.y0;
  p.width = window.width;
  p.height = window.height;
  p.texture_cone = float(std::max(texture_cone, 0.0));
  p.grid = std::clamp(grid, 1u, 4u);
  if (scene_.tracing() == Tracing::RayQuery) pipeline_.bind(cmd, {&out.set_, &scene_.ray_query_set()});
  else pipeline_.bind(cmd, {&out.set_});
  pipeline_.push(cmd, p);
  pipeline_.dispatch(cmd, window.width, window.height);
}

}  // namespace fovea::renderer
