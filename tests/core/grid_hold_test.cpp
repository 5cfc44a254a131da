// Where a foveated grid is laid out (core/grid_hold.hpp): held through a drift within 0.5°,
// laid out again past it, a non-finite gaze passed through without moving the hold.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "fovea/core/grid_hold.hpp"

namespace {

glm::dvec3 yaw(double deg) { return {std::sin(glm::radians(deg)), 0, -std::cos(glm::radians(deg))}; }
bool same(glm::dvec3 a, glm::dvec3 b) { return glm::length(a - b) < 1e-12; }

TEST(GridHold, HoldsThroughADriftAndFollowsALargerMove) {
  fovea::core::GridHold h;
  EXPECT_TRUE(same(h.place(yaw(10)), yaw(10)));
  EXPECT_TRUE(same(h.place(yaw(10.49)), yaw(10)));
  EXPECT_TRUE(same(h.place(yaw(9.6)), yaw(10)));
  EXPECT_TRUE(same(h.place(yaw(10.51)), yaw(10.51))) << "past 0.5°";
  EXPECT_TRUE(same(h.place(yaw(10.2)), yaw(10.51))) << "held at the new place";
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const glm::dvec3 lost = h.place({nan, nan, nan});
  EXPECT_TRUE(std::isnan(lost.x)) << "passed through to the distribution's fallback";
  EXPECT_TRUE(same(h.place(yaw(10.3)), yaw(10.51))) << "a lost sample does not move the hold";
  h.reset();
  EXPECT_TRUE(same(h.place(yaw(10.3)), yaw(10.3)));
}

// The hold is at most half the fovea margin: a held fovea keeps half the margin for the
// tracker's error; without a margin nothing is held.
TEST(GridHold, RadiusFollowsTheMargin) {
  using fovea::core::GridHold;
  EXPECT_EQ(GridHold::radius_for_margin(1.0), GridHold::kHoldDeg);  // the default margin
  EXPECT_EQ(GridHold::radius_for_margin(3.0), GridHold::kHoldDeg);
  EXPECT_EQ(GridHold::radius_for_margin(0.4), 0.2);
  EXPECT_EQ(GridHold::radius_for_margin(0.0), 0.0);
  GridHold narrow(GridHold::radius_for_margin(0.4));
  EXPECT_TRUE(same(narrow.place(yaw(10)), yaw(10)));
  EXPECT_TRUE(same(narrow.place(yaw(10.15)), yaw(10)));
  EXPECT_TRUE(same(narrow.place(yaw(10.3)), yaw(10.3))) << "past 0.2°";
  GridHold none(GridHold::radius_for_margin(0.0));
  EXPECT_TRUE(same(none.place(yaw(10)), yaw(10)));
  EXPECT_TRUE(same(none.place(yaw(10.01)), yaw(10.01))) << "no margin: every gaze laid out";
}

}  // namespace
