// `fovea view --scene`: under a private Xvfb the mirror window shows the path-traced scene
// through the lens (both eyes), not the direction grid, and bad options exit 2.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "cli.hpp"
#include "fovea/core/image.hpp"
#include "xvfb.hpp"

using namespace fovea;
using fovea::test::run_fovea;

namespace {

using fovea::test::Xvfb;

// Mean linear colour of the lit (non-black) pixels in columns [x0, x1) of the screenshot.
glm::dvec3 mean_lit(const core::Image& img, int x0, int x1) {
  glm::dvec3 sum(0);
  long n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = x0; x < x1; ++x) {
      const glm::vec4 p = img.at(x, y);
      if (p.x + p.y + p.z < 0.01f) continue;  // hidden area, letterbox
      sum += glm::dvec3(p.x, p.y, p.z), ++n;
    }
  return n ? sum / double(n) : sum;
}

// The tiny display (64x72 per eye) in a 128x72 window: each panel fills its half.
void expect_walls(const std::string& options) {
  Xvfb x;
  if (!x.running()) GTEST_SKIP() << "Xvfb is not available";
  const std::string dir = fovea::test::temp_dir("view");
  const std::string shot = dir + "/shot.png";
  const auto r = run_fovea("view --display tiny --scene cornell --frames 3 --screenshot " + shot + " " + options);
  ASSERT_EQ(r.status, 0) << r.err;
  const core::Image img = core::read_png(shot);
  ASSERT_EQ(img.width, 128);
  ASSERT_EQ(img.height, 72);
  for (int e = 0; e < 2; ++e) {
    // The outer sixth of each panel side: the side walls (the boxes stand in the middle).
    const int x0 = 64 * e;
    const glm::dvec3 red = mean_lit(img, x0, x0 + 16), green = mean_lit(img, x0 + 48, x0 + 64);
    EXPECT_GT(red.x, 1.5 * red.y) << options << " eye " << e << ": red wall side " << red.x << "," << red.y << ","
                                  << red.z;
    EXPECT_GT(green.y, 1.5 * green.x) << options << " eye " << e << ": green wall side " << green.x << ","
                                      << green.y << "," << green.z;
  }
  std::filesystem::remove_all(dir);
}

// The Cornell box's red wall is on the left, the green one on the right (the direction
// grid is grey and yellow).
TEST(ViewCli, CornellRedWallLeftGreenWallRight) { expect_walls("--gaze 0.5,0.5"); }

#ifndef FOVEA_SANITIZED_BUILD
// The same through the LUT cache of the optics, with a synthetic gaze source.
TEST(ViewCli, CornellThroughTheOpticsLutWithSyntheticGaze) { expect_walls("--optics lut --gaze synthetic:3"); }
#endif

TEST(ViewCli, BadOptionsExitTwo) {
  EXPECT_EQ(run_fovea("view --display tiny --optics fast --frames 1").status, 2);
  EXPECT_EQ(run_fovea("view --display tiny --scene no-such-scene.obj --frames 1").status, 2);
  EXPECT_EQ(run_fovea("view --display tiny --gaze no-such-recording.csv --frames 1").status, 2);
}

}  // namespace
