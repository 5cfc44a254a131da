// Eye optics: stereo views from a preset, the view-space visibility mask, gaze through the lens.
#include "fovea/core/eye_optics.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "fovea/core/display.hpp"
#include "fovea/core/stereo_views.hpp"

namespace core = fovea::core;

TEST(EyeOptics, GazeThroughTheLensRoundTrips) {
  const core::Lens lens = core::Lens::for_eye(core::load_display("vive"), core::Eye::Left);
  const glm::dvec3 dir = core::gaze_direction(lens, {0.3, 0.6});
  EXPECT_NEAR(glm::length(dir), 1.0, 1e-12);
  const auto uv = core::gaze_panel_uv(lens, dir);
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x, 0.3, 1e-9);
  EXPECT_NEAR(uv->y, 0.6, 1e-9);
  EXPECT_FALSE(core::gaze_panel_uv(lens, {0, 0, 1}).has_value());
}

// The eyes sit ipd/2 to either side of the head along its (rotated) x axis, with the preset's
// per-eye FOV and raster.
TEST(StereoViews, EyesBesideTheHead) {
  const core::DisplayPreset d = core::load_display("vive");
  core::Pose head;
  head.orientation = glm::angleAxis(0.5, glm::dvec3(0, 1, 0));
  head.position = {1, 2, 3};
  const core::StereoViews v = core::stereo_views(d, head);
  EXPECT_DOUBLE_EQ(v.ipd_m, d.ipd_m);
  const glm::dvec3 right_axis = head.orientation * glm::dvec3(1, 0, 0);
  for (core::Eye e : {core::Eye::Left, core::Eye::Right}) {
    const double side = e == core::Eye::Left ? -0.5 : 0.5;
    const glm::dvec3 expect = head.position + side * d.ipd_m * right_axis;
    EXPECT_NEAR(glm::length(v[e].pose().position - expect), 0.0, 1e-12);
    EXPECT_EQ(v[e].width(), d.width);
    EXPECT_EQ(v[e].height(), d.height);
    EXPECT_DOUBLE_EQ(v[e].fov().angle_left, d.fov(e).angle_left);
    EXPECT_DOUBLE_EQ(v[e].fov().angle_right, d.fov(e).angle_right);
  }
}

// The view mask is the hidden area's view-space visibility sampled at view pixel centres, in
// the row-padded layout the grid shader reads.
TEST(ViewMask, MatchesVisibilityAtPixelCentres) {
  const core::EyeOptics optics(core::load_display("tiny"), core::Eye::Left);
  const core::ViewMask m = optics.view_mask();
  ASSERT_EQ(m.width(), optics.view().width());
  ASSERT_EQ(m.words_per_row(), (m.width() + 31) / 32);
  long hidden = 0;
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) {
      const bool visible = optics.hidden().visible_view_px({x + 0.5, y + 0.5});
      ASSERT_EQ(m.hidden(x, y), !visible) << x << "," << y;
      EXPECT_EQ(m.visible_at({x + 0.9, y + 0.1}), visible);
      hidden += visible ? 0 : 1;
    }
  EXPECT_GT(hidden, 0) << "the tiny preset's lens hides its corners";
  EXPECT_NEAR(m.hidden_fraction(), double(hidden) / (m.width() * m.height()), 1e-12);
  // Padding bits beyond the raster stay clear.
  if (m.width() % 32) {
    for (int y = 0; y < m.height(); ++y)
      EXPECT_EQ(m.words()[std::size_t(y) * m.words_per_row() + m.words_per_row() - 1] >> (m.width() % 32), 0u);
  }
}
