#include "composite.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "fovea/renderer/reference.hpp"

namespace fovea::layer {

PixelFormat pixel_format(VkFormat f) {
  switch (f) {
    case VK_FORMAT_R8G8B8A8_SRGB: return {false, true};
    case VK_FORMAT_B8G8R8A8_SRGB: return {true, true};
    case VK_FORMAT_R8G8B8A8_UNORM: return {false, false};
    case VK_FORMAT_B8G8R8A8_UNORM: return {true, false};
    default: break;
  }
  throw std::runtime_error("the application's projection views use VkFormat " + std::to_string(int(f)) +
                           ", which the layer cannot composite (8-bit RGBA/BGRA, sRGB or UNORM only)");
}

Pixels8 encode_scene(const core::Image& linear, PixelFormat fmt) {
  const core::Image mapped = renderer::tone_map(linear);
  Pixels8 out{mapped.width, mapped.height, std::vector<std::uint8_t>(std::size_t(mapped.width) * std::size_t(mapped.height) * 4)};
  const auto byte = [&](float v) {
    v = std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f);
    return std::uint8_t(std::lround((fmt.srgb ? core::srgb_encode(v) : v) * 255.0f));
  };
  for (int y = 0; y < mapped.height; ++y)
    for (int x = 0; x < mapped.width; ++x) {
      const auto& c = mapped.at(x, y);
      std::uint8_t* p = out.at(x, y);
      p[fmt.bgra ? 2 : 0] = byte(c.x);
      p[1] = byte(c.y);
      p[fmt.bgra ? 0 : 2] = byte(c.z);
      p[3] = 255;
    }
  return out;
}

std::array<std::uint8_t, 3> border_colour(const Pixels8& img) {
  std::map<std::uint32_t, int> count;
  const auto add = [&](int x, int y) {
    const std::uint8_t* p = img.at(x, y);
    ++count[std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16];
  };
  for (int x = 0; x < img.width; ++x) add(x, 0), add(x, img.height - 1);
  for (int y = 1; y + 1 < img.height; ++y) add(0, y), add(img.width - 1, y);
  if (count.empty()) return {0, 0, 0};
  const auto best = std::max_element(count.begin(), count.end(), [](auto& a, auto& b) { return a.second < b.second; });
  return {std::uint8_t(best->first), std::uint8_t(best->first >> 8), std::uint8_t(best->first >> 16)};
}

namespace {

// Below a micro-radian (|w| within 1e-12 of 1) a rotation moves no pixel.
bool rotates(const glm::dquat& q) { return std::abs(std::abs(q.w) - 1.0) > 1e-12; }

}  // namespace

bool resample_copies(const core::View& app_view, int width, int height, const core::View& scene_view,
                     const glm::dquat& scene_to_app) {
  const auto same = [](const core::Fov& a, const core::Fov& b) {
    return std::abs(a.angle_left - b.angle_left) < 1e-6 && std::abs(a.angle_right - b.angle_right) < 1e-6 &&
           std::abs(a.angle_up - b.angle_up) < 1e-6 && std::abs(a.angle_down - b.angle_down) < 1e-6;
  };
  return !rotates(scene_to_app) && same(app_view.fov(), scene_view.fov()) && width == scene_view.width() &&
         height == scene_view.height();
}

Pixels8 resample(const Pixels8& app, const core::View& app_view, const core::View& scene_view,
                 const glm::dquat& scene_to_app) {
  if (resample_copies(app_view, app.width, app.height, scene_view, scene_to_app)) return app;
  const bool rotated = rotates(scene_to_app);
  Pixels8 out{scene_view.width(), scene_view.height(),
              std::vector<std::uint8_t>(std::size_t(scene_view.width()) * std::size_t(scene_view.height()) * 4, 0)};
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      const glm::dvec3 d = scene_view.pixel_to_dir({x + 0.5, y + 0.5});
      const auto px = app_view.dir_to_pixel(rotated ? scene_to_app * d : d);
      if (!px || px->x < 0 || px->y < 0 || px->x >= app.width || px->y >= app.height) continue;
      std::copy_n(app.at(int(px->x), int(px->y)), 4, out.at(x, y));
    }
  return out;
}

LayerBlend layer_blend(XrCompositionLayerFlags flags, PixelFormat fmt) {
  return {(flags & XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT) != 0,
          (flags & XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT) == 0, fmt.srgb};
}

namespace {

// One 8-bit colour channel to linear [0, 1] and back (alpha is linear in every format).
struct ChannelCodec {
  std::array<float, 256> decode{};
  bool srgb;
  explicit ChannelCodec(bool srgb_) : srgb(srgb_) {
    for (int i = 0; i < 256; ++i) decode[std::size_t(i)] = srgb ? core::srgb_decode(float(i) / 255.0f) : float(i) / 255.0f;
  }
  std::uint8_t encode(float v) const {
    v = std::clamp(v, 0.0f, 1.0f);
    return std::uint8_t(std::lround((srgb ? core::srgb_encode(v) : v) * 255.0f));
  }
};

}  // namespace

std::int64_t composite(Pixels8& scene, const Pixels8& app, Composite mode, std::array<std::uint8_t, 3> background,
                       const LayerBlend& blend, int tolerance) {
  if (app.width != scene.width || app.height != scene.height)
    throw std::logic_error("composite: the application's image and the scene differ in size");
  std::int64_t shown = 0;
  if (mode == Composite::SceneOnly) return 0;
  const ChannelCodec codec(blend.srgb);
  for (int y = 0; y < scene.height; ++y)
    for (int x = 0; x < scene.width; ++x) {
      const std::uint8_t* a = app.at(x, y);
      std::uint8_t* s = scene.at(x, y);
      if (mode == Composite::AppOnTop) {
        if (a[3] == 0) continue;
        bool differs = false;
        for (int c = 0; c < 3; ++c) differs |= std::abs(int(a[c]) - int(background[std::size_t(c)])) > tolerance;
        if (!differs) continue;
        std::copy_n(a, 4, s);
        ++shown;
        continue;
      }
      // An opaque layer covers the scene: its pixels pass through unchanged.
      const int alpha = blend.source_alpha ? a[3] : 255;
      if (alpha == 255) {
        std::copy_n(a, 3, s);
        s[3] = 255;
        ++shown;
        continue;
      }
      // Premultiplied: out = src + (1 - a) dst; straight: out = a src + (1 - a) dst. A fully
      // transparent premultiplied pixel may still add light (additive content).
      const float fa = float(alpha) / 255.0f;
      const float src_weight = blend.premultiplied ? 1.0f : fa;
      bool adds = false;
      for (int c = 0; c < 3; ++c) adds |= a[c] != 0;
      if (alpha == 0 && !(blend.premultiplied && adds)) continue;
      for (int c = 0; c < 3; ++c)
        s[c] = codec.encode(src_weight * codec.decode[a[c]] + (1.0f - fa) * codec.decode[s[c]]);
      s[3] = 255;
      ++shown;
    }
  return shown;
}

Pixels8 reproject_traced(const EyeComposition& eye) {
  Pixels8 out = resample(*eye.traced, eye.traced_view, eye.out_view, eye.to_traced);
  // Where the traced frame does not reach (the head turned past its border): opaque black.
  for (std::size_t i = 3; i < out.data.size(); i += 4) out.data[i] = 255;
  return out;
}

Pixels8 compose_eye(const EyeComposition& eye, const CompositionRule& rule) {
  Pixels8 out = reproject_traced(eye);
  if (!eye.app) return out;
  const Pixels8 a = resample(*eye.app, eye.app_view, eye.out_view);
  if (eye.by_depth())
    composite_depth(out, resample_depth(*eye.traced_depth, eye.traced_view, eye.out_view, eye.to_traced), a,
                    resample_depth(*eye.app_depth, eye.app_view, eye.out_view), eye.depth_range);
  else
    composite(out, a, rule.mode, rule.background ? *rule.background : border_colour(*eye.app), rule.blend);
  return out;
}

// resample() moves 4-byte texels by direction, so each float travels as its bytes.
std::vector<float> resample_depth(const std::vector<float>& depth, const core::View& from, const core::View& to,
                                  const glm::dquat& to_from) {
  Pixels8 packed{from.width(), from.height(), std::vector<std::uint8_t>(depth.size() * 4)};
  std::memcpy(packed.data.data(), depth.data(), packed.data.size());
  const Pixels8 moved = resample(packed, from, to, to_from);
  std::vector<float> out(moved.data.size() / 4);
  std::memcpy(out.data(), moved.data.data(), moved.data.size());
  return out;
}

double view_distance(float d, const DepthRange& r) {
  if (!(r.max_depth != r.min_depth) || !(r.near_z > 0) || !(r.far_z > 0) || r.near_z == r.far_z)
    throw std::runtime_error("XrCompositionLayerDepthInfoKHR: degenerate depth range (minDepth " +
                             std::to_string(r.min_depth) + ", maxDepth " + std::to_string(r.max_depth) + ", nearZ " +
                             std::to_string(r.near_z) + ", farZ " + std::to_string(r.far_z) + ")");
  const double t = std::clamp((double(d) - r.min_depth) / (double(r.max_depth) - r.min_depth), 0.0, 1.0);
  const auto inverse = [](float z) { return std::isinf(z) ? 0.0 : 1.0 / double(z); };
  const double inv_z = (1.0 - t) * inverse(r.near_z) + t * inverse(r.far_z);
  return inv_z > 0 ? 1.0 / inv_z : std::numeric_limits<double>::infinity();
}

std::int64_t composite_depth(Pixels8& scene, const std::vector<float>& scene_depth, const Pixels8& app,
                             const std::vector<float>& app_depth, const DepthRange& range) {
  const std::size_t n = std::size_t(scene.width) * std::size_t(scene.height);
  if (app.width != scene.width || app.height != scene.height || scene_depth.size() != n || app_depth.size() != n)
    throw std::logic_error("composite_depth: the images and depths differ in size");
  // The cleared value is the far end: max_depth normally, min_depth with reversed Z.
  const double far = std::max(view_distance(range.min_depth, range), view_distance(range.max_depth, range));
  std::int64_t shown = 0;
  for (int y = 0; y < scene.height; ++y)
    for (int x = 0; x < scene.width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(scene.width) + std::size_t(x);
      const std::uint8_t* a = app.at(x, y);
      if (a[3] == 0) continue;
      const double za = view_distance(app_depth[i], range);
      if (za >= far) continue;  // the cleared far plane: the application drew nothing here
      const double zs = scene_depth[i] > 0 ? double(scene_depth[i]) : std::numeric_limits<double>::infinity();
      if (za >= zs) continue;
      std::copy_n(a, 4, scene.at(x, y));
      ++shown;
    }
  return shown;
}

}  // namespace fovea::layer
