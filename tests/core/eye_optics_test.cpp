// Eye optics: stereo views from a preset, the view-space visibility mask, gaze through the lens.
#include "fovea/core/eye_optics.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"
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

// A runtime's hidden triangle mesh, rasterised at view pixel centres: one counter-clockwise
// triangle over the top-left corner and one clockwise over the bottom-right of a 90°×90°
// view (tangents ±1) on an 8×4 raster, against the pattern worked out by hand from the
// pixel centres' tangents (x: −1 + (i + 0.5)/4, y: 1 − (j + 0.5)/2).
TEST(ViewMask, FromHiddenTriangles) {
  const core::View view(core::Fov::from_degrees(-45, 45, 45, -45), 8, 4);
  const std::vector<glm::vec2> vertices{{-1, 1}, {-1, 0}, {0, 1}, {1, -1}, {1, 0}, {0, -1}};
  const std::vector<std::uint32_t> indices{0, 1, 2, 3, 4, 5};
  const core::ViewMask m = core::ViewMask::from_hidden_triangles(view, vertices, indices, "test mesh");
  const char* expected[4] = {"###.....", "#.......", ".......#", ".....###"};
  ASSERT_EQ(m.width(), 8);
  ASSERT_EQ(m.height(), 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) EXPECT_EQ(m.hidden(x, y), expected[y][x] == '#') << x << "," << y;
  EXPECT_DOUBLE_EQ(m.hidden_fraction(), 8.0 / 32.0);
  // An empty mesh hides nothing; a broken one is refused with its name.
  EXPECT_EQ(core::ViewMask::from_hidden_triangles(view, vertices, {}, "empty").hidden_fraction(), 0.0);
  const std::vector<std::uint32_t> beyond{0, 1, 6};
  EXPECT_THROW(core::ViewMask::from_hidden_triangles(view, vertices, beyond, "beyond"), core::InputError);
  const std::vector<std::uint32_t> partial{0, 1};
  EXPECT_THROW(core::ViewMask::from_hidden_triangles(view, vertices, partial, "partial"), core::InputError);
}

// The hidden triangle mesh the runtime serves (visibility_mesh of the lens's hidden area)
// rasterises back to the lens's own view mask, up to the polygon's edge pixels.
TEST(ViewMask, HiddenMeshRoundTrip) {
  const core::EyeOptics optics(core::load_display("tiny"), core::Eye::Left);
  const core::ViewMask direct = optics.view_mask();
  const core::VisibilityMesh mesh = core::visibility_mesh(optics.hidden(), core::VisibilityMeshType::HiddenTriangles);
  const core::ViewMask from_mesh =
      core::ViewMask::from_hidden_triangles(optics.view(), mesh.vertices, mesh.indices, "tiny mesh");
  long differ = 0;
  for (int y = 0; y < direct.height(); ++y)
    for (int x = 0; x < direct.width(); ++x) differ += direct.hidden(x, y) != from_mesh.hidden(x, y);
  ASSERT_GT(direct.hidden_fraction(), 0.0);
  EXPECT_NEAR(from_mesh.hidden_fraction(), direct.hidden_fraction(), 0.02);
  EXPECT_LT(double(differ) / (direct.width() * direct.height()), 0.02);
}
