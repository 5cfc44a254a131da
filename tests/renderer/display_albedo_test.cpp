// The display pixels' first hits near the gaze (renderer::DisplayAlbedo, pt_primary.comp): the
// window a cone of the gaze covers on the raster, and first hits that agree with the path
// tracer's at the pixel centres (the same surface code, docs/reconstruction.md "Textures at
// the display's resolution").
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "fovea/core/error.hpp"
#include "fovea/core/view.hpp"
#include "fovea/renderer/display_albedo.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "fovea/shaders/pt_primary.h"
#include "gpu_fixture.hpp"
#include "pt_helpers.hpp"

namespace fr = fovea::renderer;
namespace fc = fovea::core;

namespace {

fc::View square_view(int size, double half_deg) {
  return fc::View(fc::Fov::from_degrees(-half_deg, half_deg, half_deg, -half_deg), size, size);
}

glm::dvec3 dir_at(double yaw_deg, double pitch_deg) {
  constexpr double kDeg = std::numbers::pi / 180;
  return {std::sin(yaw_deg * kDeg) * std::cos(pitch_deg * kDeg), std::sin(pitch_deg * kDeg),
          -std::cos(yaw_deg * kDeg) * std::cos(pitch_deg * kDeg)};
}

}  // namespace

// A 10° cone at the centre of a ±45° raster of 100 pixels (0.02 tangent units each) spans
// 2·tan 10° / 0.02 = 17.6 pixels, one more each way; at a corner it is clipped to the
// raster; a cone off the raster, behind the eye or of no direction covers nothing; a box
// larger than the buffer is cropped around the axis' pixel.
TEST(ConeWindow, CentredClippedEmptyAndCropped) {
  const fc::View v = square_view(100, 45);
  const fr::PixelWindow c = fr::cone_window(v, {0, 0, -1}, 10, 10000);
  EXPECT_GE(c.width, 18u);
  EXPECT_LE(c.width, 22u);
  EXPECT_EQ(c.width, c.height);
  EXPECT_NEAR(c.x0 + 0.5 * c.width, 50.0, 1.0);
  EXPECT_NEAR(c.y0 + 0.5 * c.height, 50.0, 1.0);

  const fr::PixelWindow corner = fr::cone_window(v, dir_at(-44, 44), 10, 10000);
  EXPECT_EQ(corner.x0, 0u);
  EXPECT_EQ(corner.y0, 0u);
  EXPECT_FALSE(corner.empty());
  EXPECT_LT(corner.x0 + corner.width, 50u);

  EXPECT_TRUE(fr::cone_window(v, dir_at(80, 0), 10, 10000).empty());  // beside the raster
  EXPECT_TRUE(fr::cone_window(v, {0, 0, 1}, 10, 10000).empty());      // behind the eye
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(fr::cone_window(v, {nan, 0, -1}, 10, 10000).empty());
  EXPECT_TRUE(fr::cone_window(v, {0, 0, 0}, 10, 10000).empty());

  const fr::PixelWindow cropped = fr::cone_window(v, dir_at(5, 0), 10, 100);
  EXPECT_LE(cropped.pixels(), 100u);
  EXPECT_FALSE(cropped.empty());
  const double axis_x = 50 + std::tan(5 * std::numbers::pi / 180) / 0.02;
  EXPECT_LE(cropped.x0, axis_x);
  EXPECT_GE(cropped.x0 + cropped.width, axis_x);

  // The capacity covers the cone at the centre and 30° off it; a 1×1 raster holds one pixel.
  EXPECT_GE(fr::cone_window_capacity(v, 10), c.pixels());
  EXPECT_EQ(fr::cone_window_capacity(square_view(1, 45), 10), 1u);
  EXPECT_EQ(fr::cone_window(square_view(1, 45), {0, 0, -1}, 10, 1).pixels(), 1u);
}

class DisplayAlbedo : public fovea::test::GpuTest {};

// One ray per pixel at its centre: the base colour and material of the path tracer's first
// hit there (a Cartesian grid of the same raster, no jitter, the same one-pixel texture cone),
// on the default scene's textured floor and crate; a window inside the raster writes its own
// pixels. Three rays per axis keep the centre ray's material and average the base colour.
TEST_F(DisplayAlbedo, FirstHitsAgreeWithThePathTracersAtPixelCentres) {
  const fr::Scene s = fr::load_scene("default");
  fr::GpuScene g(ctx(), s);
  fr::DisplayAlbedo pass(ctx(), g);
  ASSERT_TRUE(pass.needed());
  const fc::View v = square_view(48, 30);
  fr::PathConfig c;
  c.texture_cone = 1.0;
  const auto traced = fovea::test::trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c);
  const fr::PixelWindow window{8, 12, 30, 24};
  fr::PrimaryHits one = pass.bind(window.pixels()), three = pass.bind(window.pixels());
  ctx().submit_and_wait([&](VkCommandBuffer cmd) {
    pass.record(cmd, one, v, window, 1);
    pass.record(cmd, three, v, window, 3);
  });
  const auto hits = one.hits().download<glm::vec4>(), hits3 = three.hits().download<glm::vec4>();
  int surfaces = 0, agree = 0;
  for (std::uint32_t y = 0; y < window.height; ++y)
    for (std::uint32_t x = 0; x < window.width; ++x) {
      const glm::vec4 h = hits[y * window.width + x], h3 = hits3[y * window.width + x];
      const std::size_t px = std::size_t(window.y0 + y) * 48 + window.x0 + x;
      for (int k = 0; k < 4; ++k) ASSERT_TRUE(std::isfinite(h[k]) && std::isfinite(h3[k]));
      EXPECT_EQ(h.w, h3.w);
      const float material = traced.position_material[px].w;
      if (material < 0) {
        EXPECT_EQ(h.w, fovea::shaders::kPtPrimaryNoHit);
        continue;
      }
      ++surfaces;
      const glm::vec4 a = traced.albedo[px];
      agree += h.w == material && std::abs(h.x - a.x) < 1e-3f && std::abs(h.y - a.y) < 1e-3f &&
               std::abs(h.z - a.z) < 1e-3f;
    }
  ASSERT_GT(surfaces, int(window.pixels()) / 4);
  EXPECT_GE(agree, surfaces - surfaces / 100) << agree << " of " << surfaces;  // rounding at edges
}

// A window larger than the buffer or outside the raster is refused, naming both.
TEST_F(DisplayAlbedo, RefusesAWindowBeyondItsBuffer) {
  const fr::Scene s = fr::load_scene("default");
  fr::GpuScene g(ctx(), s);
  fr::DisplayAlbedo pass(ctx(), g);
  fr::PrimaryHits out = pass.bind(16);
  const fc::View v = square_view(8, 30);
  for (const fr::PixelWindow w : {fr::PixelWindow{0, 0, 5, 5}, fr::PixelWindow{6, 0, 4, 2}}) {
    try {
      ctx().submit_and_wait([&](VkCommandBuffer cmd) { pass.record(cmd, out, v, w); });
      FAIL() << "accepted " << w.width << "x" << w.height;
    } catch (const fc::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("display albedo: window"), std::string::npos) << e.what();
    }
  }
}
