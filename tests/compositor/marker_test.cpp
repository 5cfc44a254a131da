#include <map>
#include <string>

#include <gtest/gtest.h>

#include "fovea/compositor/marker.hpp"
#include "fovea/core/error.hpp"

using namespace fovea::compositor;
using fovea::core::Image;

namespace {

const glm::vec4 kScene{0.25f, 0.5f, 0.75f, 1};

// Counts the pixels equal to `c` and checks that they form exactly the rectangle given.
void expect_square(const Image& img, int x0, int y0, int w, int h, glm::vec4 c) {
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const bool inside = x >= x0 && x < x0 + w && y >= y0 && y < y0 + h;
      ASSERT_EQ(img.at(x, y), inside ? c : kScene) << x << "," << y;
    }
}

std::map<std::string, std::string> g_env;
const char* fake_env(const char* name) {
  auto it = g_env.find(name);
  return it == g_env.end() ? nullptr : it->second.c_str();
}

}  // namespace

TEST(Marker, ExactPixelsInEachCorner) {
  const struct {
    MarkerCorner corner;
    int x0, y0;
  } cases[] = {{MarkerCorner::TopLeft, 0, 0}, {MarkerCorner::TopRight, 7, 0}, {MarkerCorner::BottomLeft, 0, 3}, {MarkerCorner::BottomRight, 7, 3}};
  for (const auto& c : cases) {
    Image img(10, 6, kScene);
    draw_marker(img, c.corner, 3, true);
    expect_square(img, c.x0, c.y0, 3, 3, {1, 1, 1, 1});
    draw_marker(img, c.corner, 3, false);  // dark: the same square, black
    expect_square(img, c.x0, c.y0, 3, 3, {0, 0, 0, 1});
  }
}

TEST(Marker, ClippedToThePanel) {
  Image img(5, 3, kScene);
  draw_marker(img, MarkerCorner::BottomRight, 4, true);  // taller than the panel
  expect_square(img, 1, 0, 4, 3, {1, 1, 1, 1});
  Image all(4, 4, kScene);
  draw_marker(all, MarkerCorner::TopRight, 100, true);
  expect_square(all, 0, 0, 4, 4, {1, 1, 1, 1});
  Image one(1, 1, kScene);
  draw_marker(one, MarkerCorner::BottomLeft, 1, true);
  EXPECT_EQ(one.at(0, 0), glm::vec4(1, 1, 1, 1));
  Image none(3, 3, kScene);
  draw_marker(none, MarkerCorner::TopLeft, 0, true);  // nothing to draw
  expect_square(none, 0, 0, 0, 0, {1, 1, 1, 1});
  Image empty;
  draw_marker(empty, MarkerCorner::TopLeft, 8, true);  // a 0×0 panel: no crash
}

TEST(Marker, ConfigFromTheEnvironment) {
  g_env.clear();
  MarkerConfig c = marker_config(fake_env);
  EXPECT_EQ(c.mode, MarkerMode::Off);
  g_env = {{"FOVEA_MARKER", "saccade"}, {"FOVEA_MARKER_CORNER", "tr"}, {"FOVEA_MARKER_SIZE", "64"}, {"FOVEA_MARKER_FRAMES", "2"}};
  c = marker_config(fake_env);
  EXPECT_EQ(c.mode, MarkerMode::Saccade);
  EXPECT_EQ(c.corner, MarkerCorner::TopRight);
  EXPECT_EQ(c.size_px, 64);
  EXPECT_EQ(c.frames, 2);
  for (auto [k, v] : {std::pair{"FOVEA_MARKER", "on"}, std::pair{"FOVEA_MARKER_CORNER", "top"}, std::pair{"FOVEA_MARKER_SIZE", "0"},
                      std::pair{"FOVEA_MARKER_SIZE", "12px"}, std::pair{"FOVEA_MARKER_FRAMES", "-1"}}) {
    g_env = {{k, v}};
    try {
      marker_config(fake_env);
      ADD_FAILURE() << k << "=" << v << " accepted";
    } catch (const fovea::core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(k), std::string::npos) << e.what();
    }
  }
}

TEST(Marker, ScheduleLightsFramesPerEvent) {
  MarkerConfig c;
  c.mode = MarkerMode::Saccade;
  c.frames = 3;
  MarkerSchedule s(c);
  EXPECT_FALSE(s.next_frame().lit);
  s.trigger(1000);
  MarkerSchedule::Frame f = s.next_frame();
  EXPECT_TRUE(f.lit && f.first);
  EXPECT_EQ(f.event_sample_ns, 1000);
  s.trigger(2000);  // while lit: ignored, one edge per logged event
  f = s.next_frame();
  EXPECT_TRUE(f.lit && !f.first);
  EXPECT_TRUE(s.next_frame().lit);
  EXPECT_FALSE(s.next_frame().lit);
  s.trigger(3000);
  f = s.next_frame();
  EXPECT_TRUE(f.first);
  EXPECT_EQ(f.event_sample_ns, 3000);

  c.mode = MarkerMode::Periodic;
  c.frames = 2;
  MarkerSchedule p(c);
  std::string pattern;
  for (int i = 0; i < 8; ++i) {
    const MarkerSchedule::Frame g = p.next_frame();
    pattern += g.first ? 'F' : g.lit ? 'L' : '.';
    EXPECT_FALSE(g.event_sample_ns.has_value());
  }
  EXPECT_EQ(pattern, "FL..FL..");
  c.mode = MarkerMode::Off;
  MarkerSchedule off(c);
  off.trigger(5);
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(off.next_frame().lit);
}
