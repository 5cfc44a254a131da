// The layer's host-side parts without an OpenXR session: configuration, compositing, gaze hold.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "composite.hpp"
#include "config.hpp"
#include "fovea/core/error.hpp"
#include "gaze_hold.hpp"

namespace fovea::layer {
namespace {

TEST(LayerConfig, ApplicationSectionOverridesDefault) {
  const std::string text = R"({"default": {"scene": "default", "composite": "alpha"},
                               "applications": {"HelloXR": {"scene": "cornell", "app_background": [1, 2, 3]}}})";
  const LayerConfig a = parse_config(text, "layer.json", "HelloXR");
  EXPECT_EQ(a.scene, "cornell");
  EXPECT_EQ(a.composite, Composite::Alpha);
  ASSERT_TRUE(a.app_background.has_value());
  EXPECT_EQ((*a.app_background)[2], 3);
  EXPECT_EQ(a.origin, "layer.json: applications.HelloXR");
  const LayerConfig b = parse_config(text, "layer.json", "Other");
  EXPECT_EQ(b.scene, "default");
  EXPECT_FALSE(b.app_background.has_value());
}

TEST(LayerConfig, ErrorsNameFileAndField) {
  const auto message = [](const std::string& text) {
    try {
      parse_config(text, "cfg.json", "App");
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("{").find("cfg.json"), std::string::npos);
  EXPECT_NE(message(R"({"default": {"composite": "over"}})").find("default.composite"), std::string::npos);
  EXPECT_NE(message(R"({"applications": {"App": {"app_background": [1, 2, 300]}}})").find("applications.App.app_background"),
            std::string::npos);
  EXPECT_NE(message(R"({"default": {"sceen": "x"}})").find("unknown key"), std::string::npos);
  EXPECT_NE(message(R"({"defaults": {}})").find("unknown key"), std::string::npos);
}

// Fuzz finding: 4294967297 used to wrap to 1 through get<int>().
TEST(LayerConfig, BackgroundComponentsAreRangeCheckedInSixtyFourBits) {
  for (const char* bad : {"[4294967297, 0, 0]", "[0, -4294967295, 0]", "[0, 0, 18446744073709551615]",
                          "[0, 0, 1.5]", "[0, 0, 1e400]"}) {
    const std::string text = std::string(R"({"default": {"app_background": )") + bad + "}}";
    try {
      parse_config(text, "cfg.json", "App");
      ADD_FAILURE() << bad << " accepted";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cfg.json"), std::string::npos) << e.what();
    }
  }
  const auto c = parse_config(R"({"default": {"app_background": [0, 128, 255]}})", "cfg.json", "App");
  ASSERT_TRUE(c.app_background.has_value());
  EXPECT_EQ(*c.app_background, (std::array<int, 3>{0, 128, 255}));
}

Pixels8 filled(int w, int h, std::array<std::uint8_t, 4> c) {
  Pixels8 p{w, h, {}};
  for (int i = 0; i < w * h; ++i) p.data.insert(p.data.end(), c.begin(), c.end());
  return p;
}

TEST(LayerComposite, AppOnTopKeysTheBackground) {
  Pixels8 app = filled(8, 6, {47, 79, 79, 255});
  std::copy_n(std::array<std::uint8_t, 4>{0, 0, 255, 255}.data(), 4, app.at(3, 2));
  std::copy_n(std::array<std::uint8_t, 4>{48, 80, 79, 255}.data(), 4, app.at(5, 2));  // within tolerance
  const auto bg = border_colour(app);
  EXPECT_EQ(bg, (std::array<std::uint8_t, 3>{47, 79, 79}));
  Pixels8 scene = filled(8, 6, {200, 100, 50, 255});
  EXPECT_EQ(composite(scene, app, Composite::AppOnTop, bg), 1);
  EXPECT_EQ(scene.at(3, 2)[2], 255);
  EXPECT_EQ(scene.at(5, 2)[0], 200);
  EXPECT_EQ(scene.at(0, 0)[0], 200);
  Pixels8 only = filled(8, 6, {200, 100, 50, 255});
  EXPECT_EQ(composite(only, app, Composite::SceneOnly, bg), 0);
  EXPECT_EQ(only.data, filled(8, 6, {200, 100, 50, 255}).data);
}

TEST(LayerComposite, AlphaBlendsStraightAlpha) {
  Pixels8 app = filled(2, 2, {255, 0, 0, 0});
  std::copy_n(std::array<std::uint8_t, 4>{255, 0, 0, 255}.data(), 4, app.at(0, 0));
  std::copy_n(std::array<std::uint8_t, 4>{255, 0, 0, 128}.data(), 4, app.at(1, 0));
  Pixels8 scene = filled(2, 2, {0, 0, 200, 255});
  EXPECT_EQ(composite(scene, app, Composite::Alpha, {0, 0, 0}), 2);
  EXPECT_EQ(scene.at(0, 0)[0], 255);
  EXPECT_EQ(scene.at(1, 0)[0], 128);
  EXPECT_EQ(scene.at(1, 0)[2], 100);
  EXPECT_EQ(scene.at(0, 1)[2], 200);
}

TEST(LayerComposite, EncodesSceneForTheSwapchainFormat) {
  core::Image img(2, 1);
  img.at(0, 0) = {1.0f, 0.0f, 0.0f, 1.0f};  // Reinhard: 1 / (1 + L) keeps the hue
  img.at(1, 0) = {NAN, 0.0f, 0.0f, 1.0f};
  const Pixels8 rgba = encode_scene(img, pixel_format(VK_FORMAT_R8G8B8A8_SRGB));
  const Pixels8 bgra = encode_scene(img, pixel_format(VK_FORMAT_B8G8R8A8_UNORM));
  EXPECT_GT(rgba.at(0, 0)[0], 0);
  EXPECT_EQ(rgba.at(0, 0)[2], 0);
  EXPECT_EQ(bgra.at(0, 0)[0], 0);
  EXPECT_GT(bgra.at(0, 0)[2], 0);
  EXPECT_GT(rgba.at(0, 0)[0], bgra.at(0, 0)[2]);  // sRGB encoding brightens mid tones
  EXPECT_EQ(rgba.at(1, 0)[0], 0);                 // never NaN garbage
  EXPECT_EQ(rgba.at(1, 0)[3], 255);
  EXPECT_THROW(pixel_format(VK_FORMAT_D32_SFLOAT), std::runtime_error);
}

TEST(LayerComposite, ResamplesByDirection) {
  const core::Fov wide = core::Fov::from_degrees(-40, 40, 40, -40), narrow = core::Fov::from_degrees(-20, 20, 20, -20);
  Pixels8 app = filled(40, 40, {10, 10, 10, 255});
  std::copy_n(std::array<std::uint8_t, 4>{250, 0, 0, 255}.data(), 4, app.at(20, 20));
  const Pixels8 same = resample(app, core::View(wide, 40, 40), core::View(wide, 40, 40));
  EXPECT_EQ(same.data, app.data);
  // The narrow view sees the wide view's centre magnified, and nothing outside it is missing.
  const Pixels8 zoom = resample(app, core::View(wide, 40, 40), core::View(narrow, 40, 40));
  EXPECT_EQ(zoom.at(20, 20)[0], 250);
  EXPECT_EQ(zoom.at(0, 0)[3], 255);
  // The wide view seen from the narrow one: its border is not covered.
  const Pixels8 out = resample(app, core::View(narrow, 40, 40), core::View(wide, 40, 40));
  EXPECT_EQ(out.at(0, 0)[3], 0);
}

TEST(LayerGazeHold, HoldsThenEasesToFixedFoveation) {
  GazeHold h;
  const glm::dvec3 fixed(0, 0, -1), right = glm::normalize(glm::dvec3(0.5, 0, -1));
  EXPECT_LT(glm::distance(h.update(0, false, right), fixed), 1e-12);  // nothing seen yet
  EXPECT_LT(glm::distance(h.update(1'000'000'000, true, right), right), 1e-12);
  EXPECT_LT(glm::distance(h.update(1'500'000'000, false, {}), right), 1e-12);  // 500 ms: held
  EXPECT_LT(glm::distance(h.update(1'600'000'000, false, {}), right), 1e-12);  // 600 ms: still held
  const glm::dvec3 mid = h.update(1'800'000'000, false, {});  // half-way through the ease
  EXPECT_GT(mid.x, 0.01);
  EXPECT_LT(mid.x, right.x - 0.01);
  EXPECT_NEAR(glm::length(mid), 1.0, 1e-12);
  EXPECT_LT(glm::distance(h.update(2'100'000'000, false, {}), fixed), 1e-12);
  EXPECT_LT(glm::distance(h.update(2'200'000'000, true, right), right), 1e-12);  // back on the tracker at once
  EXPECT_LT(glm::distance(h.update(2'300'000'000, true, glm::dvec3(NAN, 0, -1)), right), 1e-12);  // a bad sample is a loss
}

// The window depth an application stores for view distance z (the inverse of view_distance).
float window_depth(double z, const DepthRange& r) {
  const auto inverse = [](double v) { return std::isinf(v) ? 0.0 : 1.0 / v; };
  const double t = (inverse(z) - inverse(r.near_z)) / (inverse(r.far_z) - inverse(r.near_z));
  return float(r.min_depth + t * (double(r.max_depth) - r.min_depth));
}

TEST(LayerDepth, ViewDistanceMapsTheRangeEnds) {
  const double inf = std::numeric_limits<double>::infinity();
  const float finf = std::numeric_limits<float>::infinity();
  for (const DepthRange r : {DepthRange{0, 1, 0.1f, 100}, DepthRange{0, 1, 100, 0.1f}, DepthRange{0.25f, 0.75f, 0.05f, 20},
                             DepthRange{0, 1, 0.1f, finf}, DepthRange{0, 1, finf, 0.1f}}) {
    const double zn = view_distance(r.min_depth, r), zf = view_distance(r.max_depth, r);
    if (std::isinf(r.near_z)) EXPECT_EQ(zn, inf); else EXPECT_NEAR(zn, r.near_z, 1e-5 * r.near_z);
    if (std::isinf(r.far_z)) EXPECT_EQ(zf, inf); else EXPECT_NEAR(zf, r.far_z, 1e-5 * r.far_z);
    for (double z : {0.5, 1.0, 3.0, 17.0}) EXPECT_NEAR(view_distance(window_depth(z, r), r), z, 1e-4 * z);
  }
  EXPECT_THROW(view_distance(0.5f, DepthRange{0, 1, 1, 1}), std::runtime_error);
  EXPECT_THROW(view_distance(0.5f, DepthRange{0.5f, 0.5f, 0.1f, 10}), std::runtime_error);
  EXPECT_THROW(view_distance(0.5f, DepthRange{0, 1, 0, 10}), std::runtime_error);
}

TEST(LayerDepth, KeepsTheNearerSurfaceForEveryDepthConvention) {
  const float finf = std::numeric_limits<float>::infinity();
  // Scene: surfaces at 2 m and 5 m, sky (0) in pixel 2.
  const std::vector<float> scene_depth{2, 2, 0, 5, 5};
  for (const DepthRange r : {DepthRange{0, 1, 0.1f, 100}, DepthRange{0, 1, 100, 0.1f}, DepthRange{0.25f, 0.75f, 0.05f, 200},
                             DepthRange{0, 1, 0.1f, finf}, DepthRange{0, 1, finf, 0.1f}}) {
    Pixels8 app = filled(5, 1, {10, 20, 30, 255});
    app.at(4, 0)[3] = 0;  // not covered by the application
    // App surfaces at 1 m (nearer), 3 m (behind the scene), 50 m (in front of the sky),
    // cleared (the far end), 1 m but alpha 0.
    const bool reversed = r.near_z > r.far_z;
    const float cleared = reversed ? r.min_depth : r.max_depth;
    const std::vector<float> app_depth{window_depth(1, r), window_depth(3, r), window_depth(50, r), cleared,
                                       window_depth(1, r)};
    Pixels8 scene = filled(5, 1, {200, 100, 50, 255});
    EXPECT_EQ(composite_depth(scene, scene_depth, app, app_depth, r), 2)
        << "near " << r.near_z << " far " << r.far_z;
    EXPECT_EQ(scene.at(0, 0)[0], 10);
    EXPECT_EQ(scene.at(1, 0)[0], 200);
    EXPECT_EQ(scene.at(2, 0)[0], 10);
    EXPECT_EQ(scene.at(3, 0)[0], 200);
    EXPECT_EQ(scene.at(4, 0)[0], 200);
  }
  Pixels8 scene = filled(2, 1, {0, 0, 0, 255});
  EXPECT_THROW(composite_depth(scene, {1}, filled(2, 1, {0, 0, 0, 255}), {0, 0}, DepthRange{}), std::logic_error);
}

}  // namespace
}  // namespace fovea::layer
