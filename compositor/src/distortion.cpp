#include "fovea/compositor/distortion.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/shaders/distortion_bindings.h"

namespace fovea::compositor {

namespace {

struct Push {  // lens_distort.comp's push_constant block
  std::uint32_t width, height, src_width, src_height, select, words_per_row, lut_size;
};

// lens_distort.comp's Optics buffer: 16 floats per channel.
std::array<float, 48> pack_optics(const core::Lens& lens) {
  std::array<float, 48> o{};
  for (int c = 0; c < 3; ++c) {
    const core::Lens::Channel& ch = lens.channel(c);
    float* p = o.data() + 16 * c;
    const double v[15] = {ch.display_centre.x, ch.display_centre.y, ch.to_radial.x,     ch.to_radial.y,
                          ch.source_centre.x,  ch.source_centre.y,  ch.from_radial.x,   ch.from_radial.y,
                          ch.vive_profile ? 1.0 : 0.0, ch.k[0], ch.k[1], ch.k[2], ch.k[3], ch.k[4],
                          // A float that is never exceeded stands in for an unbounded edge.
                          std::min(ch.r_edge, 1e30)};
    for (int i = 0; i < 15; ++i) p[i] = float(v[i]);
  }
  return o;
}

glm::vec4 texel(const core::Image& img, int x, int y) {
  const glm::vec4 v = img.at(std::clamp(x, 0, img.width - 1), std::clamp(y, 0, img.height - 1));
  glm::vec4 out;
  for (int c = 0; c < 4; ++c) out[c] = std::isfinite(v[c]) ? std::clamp(v[c], 0.0f, 1e6f) : 0.0f;
  return out;
}

double tap(const core::Image& img, int c, glm::dvec2 uv) {
  if (!(uv.x >= 0 && uv.y >= 0 && uv.x <= 1 && uv.y <= 1)) return 0;
  const glm::dvec2 p = uv * glm::dvec2(img.width, img.height) - 0.5;
  const glm::dvec2 i0 = glm::floor(p), f = p - i0;
  const int x = int(i0.x), y = int(i0.y);
  const double a = texel(img, x, y)[c], b = texel(img, x + 1, y)[c];
  const double d = texel(img, x, y + 1)[c], e = texel(img, x + 1, y + 1)[c];
  return (a + (b - a) * f.x) * (1 - f.y) + (d + (e - d) * f.x) * f.y;
}

void check_raster(const core::HiddenAreaMask& mask, int w, int h, const char* what) {
  if (w != mask.width() || h != mask.height())
    throw core::InputError(std::string("distortion pass: ") + what + " is " + std::to_string(w) + "x" +
                           std::to_string(h) + ", the view raster is " + std::to_string(mask.width()) + "x" +
                           std::to_string(mask.height()));
}

}  // namespace

core::Image PanelImage::to_image() const {
  core::Image img(width, height);
  for (size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 4; ++c) {
      const float v = rgba[i * 4 + c] / 255.0f;
      img.pixels[i][c] = c < 3 ? core::srgb_decode(v) : v;
    }
  return img;
}

core::Image distort_reference(const core::HiddenAreaMask& mask, const core::Image& view_image, ChannelSelect select,
                              const core::LensLut* lut) {
  check_raster(mask, view_image.width, view_image.height, "the view image");
  const core::Lens& lens = mask.lens();
  const int W = mask.width(), H = mask.height();
  core::Image out(W, H, {0, 0, 0, 1});
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (mask.hidden(x, y)) continue;
      const glm::dvec2 uv((x + 0.5) / W, (y + 0.5) / H);
      for (int c = 0; c < 3; ++c) {
        const int optic = select == ChannelSelect::All ? c : int(select);
        const glm::dvec2 src = lut ? lut->source_uv(optic, uv) : lens.source_uv(optic, uv);
        out.at(x, y)[c] = float(std::clamp(tap(view_image, c, src), 0.0, 1.0));
      }
    }
  return out;
}

core::Image direction_grid(const core::View& v, double step_deg) {
  core::Image img(v.width(), v.height(), {0.02f, 0.02f, 0.03f, 1});
  const double step = std::clamp(step_deg, 0.1, 90.0) * std::numbers::pi / 180;
  const double px_per_tan_x = v.width() / (v.tan_right() - v.tan_left());
  const double px_per_tan_y = v.height() / (v.tan_up() - v.tan_down());
  const double width_px = std::max(0.6, v.width() / 500.0);
  for (int y = 0; y < v.height(); ++y)
    for (int x = 0; x < v.width(); ++x) {
      const double tx = v.tan_left() + (x + 0.5) / px_per_tan_x, ty = v.tan_up() - (y + 0.5) / px_per_tan_y;
      // Distance in pixels to the nearest line of constant angle, per axis (dθ = dt/(1+t²)).
      const double ax = std::atan(tx) / step, ay = std::atan(ty) / step;
      const double dx = std::abs(ax - std::round(ax)) * step * (1 + tx * tx) * px_per_tan_x;
      const double dy = std::abs(ay - std::round(ay)) * step * (1 + ty * ty) * px_per_tan_y;
      const double d = std::min(dx, dy);
      const bool axis = (std::round(ax) == 0 && dx <= d) || (std::round(ay) == 0 && dy <= d);
      const float a = float(std::exp(-0.5 * (d / width_px) * (d / width_px)));
      if (a > 0.01f) img.at(x, y) = axis ? glm::vec4(a, a, 0.2f * a, 1) : glm::vec4(a, a, a, 1);
    }
  return img;
}

DistortionPass::DistortionPass(gpu::Context& ctx, const core::HiddenAreaMask& mask, ChannelSelect select,
                               OpticsEval eval)
    : ctx_(&ctx), width_(mask.width()), height_(mask.height()), select_(select) {
  pipeline_ = gpu::ComputePipeline(
      ctx, {.shader = "lens_distort.comp.spv",
            .sets = {{gpu::Binding::StorageImage, gpu::Binding::StorageImage, gpu::Binding::StorageBuffer,
                      gpu::Binding::StorageBuffer, gpu::Binding::StorageBuffer}},
            .push_constant_bytes = sizeof(Push)});
  const auto optics = pack_optics(mask.lens());
  optics_ = gpu::Buffer(ctx, {.size = sizeof(optics), .name = "lens optics"});
  optics_.upload(optics);
  const auto words = mask.words();
  mask_ = gpu::Buffer(ctx, {.size = words.size_bytes(), .name = "hidden-area mask"});
  mask_.upload(words);
  words_per_row_ = std::uint32_t(mask.words_per_row());
  // Direct evaluation binds a one-float placeholder: the shader never reads it then.
  std::vector<float> lut(1, 0.0f);
  if (eval == OpticsEval::Lut) {
    const core::LensLut cache(mask.lens());
    lut = cache.packed();
    lut_size_ = std::uint32_t(cache.size());
  }
  lut_ = gpu::Buffer(ctx, {.size = lut.size() * sizeof(float), .name = "lens optics LUT"});
  lut_.upload(lut);
}

void DistortionPass::record(VkCommandBuffer cmd, const gpu::Image2D& source, const gpu::Image2D& target) {
  if (int(target.width()) != width_ || int(target.height()) != height_)
    throw core::InputError("distortion pass: the panel image must be " + std::to_string(width_) + "x" +
                           std::to_string(height_));
  const std::pair<VkImageView, VkImageView> key{source.view(), target.view()};
  size_t i = 0;
  while (i < set_keys_.size() && set_keys_[i] != key) ++i;
  if (i == set_keys_.size()) {
    auto set = std::make_unique<gpu::DescriptorSet>(*ctx_, pipeline_.set_layout(0));
    set->bind(DISTORT_BINDING_SOURCE, source).bind(DISTORT_BINDING_PANEL, target);
    set->bind(DISTORT_BINDING_OPTICS, optics_).bind(DISTORT_BINDING_MASK, mask_).bind(DISTORT_BINDING_LUT, lut_);
    sets_.push_back(std::move(set));
    set_keys_.push_back(key);
  }
  const Push push{std::uint32_t(width_), std::uint32_t(height_), source.width(), source.height(),
                  std::uint32_t(select_), words_per_row_, lut_size_};
  pipeline_.run(cmd, {sets_[i].get()}, push, std::uint32_t(width_), std::uint32_t(height_));
}

PanelImage DistortionPass::run(const core::Image& view_image) {
  if (view_image.width < 1 || view_image.height < 1) throw core::InputError("distortion pass: empty view image");
  gpu::Image2D source(*ctx_, {.width = std::uint32_t(view_image.width), .height = std::uint32_t(view_image.height),
                              .format = VK_FORMAT_R32G32B32A32_SFLOAT, .name = "distortion source"});
  gpu::Image2D target(*ctx_, {.width = std::uint32_t(width_), .height = std::uint32_t(height_),
                              .format = VK_FORMAT_R8G8B8A8_UNORM, .name = "panel"});
  source.upload(view_image.pixels);
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) { record(cmd, source, target); });
  PanelImage out{width_, height_, std::vector<std::uint8_t>(size_t(width_) * height_ * 4)};
  target.download_bytes(std::as_writable_bytes(std::span(out.rgba)));
  // The images die here: forget their descriptor set.
  for (size_t i = 0; i < set_keys_.size(); ++i)
    if (set_keys_[i].first == source.view()) {
      sets_.erase(sets_.begin() + long(i));
      set_keys_.erase(set_keys_.begin() + long(i));
      break;
    }
  return out;
}

}  // namespace fovea::compositor
