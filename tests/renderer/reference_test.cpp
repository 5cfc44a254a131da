// Progressive reference rendering, its stop criterion, EXR output, and the CLI's exit
// codes for bad scenes.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <tinyexr.h>

#include "fovea/core/error.hpp"
#include "fovea/renderer/procedural.hpp"
#include "fovea/renderer/reference.hpp"
#include "gpu_fixture.hpp"

namespace fr = fovea::renderer;
namespace fc = fovea::core;

class Reference : public fovea::test::GpuTest {};

TEST_F(Reference, StopsAtTheRelativeErrorAndWritesExr) {
  const fr::Scene s = fr::make_cornell();
  fr::GpuScene g(ctx(), s);
  const fc::View v(fc::Fov::from_degrees(-45, 45, 45, -45), 16, 16, s.camera);
  fr::ReferenceOptions o;
  o.path.spp = 4;
  o.max_spp = 4096;
  o.until_rel_error = 0.02;
  int calls = 0;
  const auto r = fr::render_reference(ctx(), g, v, fc::Eye::Left, o, [&](const fr::ReferenceProgress&) { ++calls; });
  EXPECT_LE(r.rel_error, 0.02);
  EXPECT_LT(r.spp, 4096u);
  EXPECT_EQ(calls, int(r.spp / 4));
  EXPECT_GT(r.mean_rgb.x, r.mean_rgb.z);  // warm light, red wall
  // A longer run has a smaller error, roughly by √(spp ratio).
  o.until_rel_error = 0;
  o.max_spp = r.spp * 4;
  const auto r4 = fr::render_reference(ctx(), g, v, fc::Eye::Left, o);
  EXPECT_LT(r4.rel_error, r.rel_error);
  EXPECT_NEAR(r4.mean_rgb.x / r.mean_rgb.x, 1.0, 0.05);

  const auto path = std::filesystem::temp_directory_path() / ("fovea_ref_" + std::to_string(::getpid()) + ".exr");
  fr::write_exr(path.string(), r.image);
  float* rgba = nullptr;
  int w = 0, h = 0;
  const char* err = nullptr;
  ASSERT_EQ(LoadEXR(&rgba, &w, &h, path.string().c_str(), &err), TINYEXR_SUCCESS);
  EXPECT_EQ(w, 16);
  EXPECT_EQ(h, 16);
  EXPECT_FLOAT_EQ(rgba[4 * 37], r.image.pixels[37].x);
  std::free(rgba);
  std::filesystem::remove(path);
}

// Window math: the pixels whose centre lies within the radius of a disc's centre.
TEST(ReferenceWindow, DiscsHoldThePixelCentresWithinTheirRadius) {
  // ±45° square view: 45° around the forward direction is the inscribed circle of the
  // tangent plane, x² + y² ≤ 1 at z = −1.
  const fc::View v(fc::Fov::from_degrees(-45, 45, 45, -45), 16, 16);
  const auto in = fr::window_coverage({{{{0, 0, -2}, 45.0}}}, v, "--window");
  ASSERT_EQ(in.size(), 256u);
  int count = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const double tx = (x + 0.5) / 8.0 - 1.0, ty = (y + 0.5) / 8.0 - 1.0;
      EXPECT_EQ(in[std::size_t(y) * 16 + x], tx * tx + ty * ty <= 1.0) << x << "," << y;
      count += in[std::size_t(y) * 16 + x];
    }
  EXPECT_EQ(count, 208);  // 4 × 52 per quadrant
  // A disc at the corner of the view (edge of view): only the pixels near it; a union adds.
  const glm::dvec3 corner = v.pixel_to_dir({0, 0});
  const double first = fc::angle_deg(corner, v.pixel_to_dir({0.5, 0.5}));
  const double second = fc::angle_deg(corner, v.pixel_to_dir({1.5, 0.5}));
  const auto edge = fr::window_coverage({{{corner, 0.5 * (first + second)}}}, v, "--window");
  EXPECT_EQ(std::count(edge.begin(), edge.end(), true), 1);
  EXPECT_TRUE(edge[0]);
  const auto both = fr::window_coverage({{{corner, 0.5 * (first + second)}, {{0, 0, -1}, 45.0}}}, v, "--window");
  for (std::size_t i = 0; i < both.size(); ++i) EXPECT_EQ(both[i], in[i] || edge[i]) << i;
  EXPECT_EQ(fr::window_coverage({}, v, "--window"), std::vector<bool>(256, true));
  // A 1×1 display: its one pixel centre is the centre of the view.
  const fc::View one(fc::Fov::from_degrees(-30, 30, 20, -20), 1, 1);
  EXPECT_EQ(fr::window_coverage({{{one.centre_dir(), 1e-3}}}, one, "--window"), std::vector<bool>{true});
  EXPECT_THROW(fr::window_coverage({{{{0.3, 0, -1}, 5.0}}}, one, "--window"), fc::InputError);
}

TEST(ReferenceWindow, BadDiscsAreInputErrorsNamingTheInput) {
  const fc::View v(fc::Fov::from_degrees(-45, 45, 45, -45), 16, 16);
  const auto message = [&](const fr::ReferenceWindow& w) {
    try {
      fr::window_coverage(w, v, "--window");
    } catch (const fc::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  for (double r : {0.0, -3.0, double(NAN), double(INFINITY), 181.0})
    EXPECT_NE(message({{{{0, 0, -1}, r}}}).find("--window: the radius"), std::string::npos) << r;
  EXPECT_NE(message({{{{0, 0, 0}, 5.0}}}).find("--window: the centre"), std::string::npos);
  EXPECT_NE(message({{{{NAN, 0, -1}, 5.0}}}).find("--window: the centre"), std::string::npos);
  // Behind the eye, and beside the view: off the view; the second of two discs is named.
  EXPECT_NE(message({{{{0, 0, 1}, 30.0}}}).find("--window: off the view"), std::string::npos);
  EXPECT_NE(message({{{{0, 0, -1}, 10.0}, {{1, 0, -0.5}, 5.0}}}).find("--window, disc 2: off the view"), std::string::npos);
}

// A window traces only its pixels, with the values the whole view's reference has there
// (the same random numbers per pixel); its statistics are over its pixels.
TEST_F(Reference, WindowTracesOnlyItsPixelsWithTheWholeViewsValues) {
  const fr::Scene s = fr::make_cornell();
  fr::GpuScene g(ctx(), s);
  const fc::View v(fc::Fov::from_degrees(-45, 45, 45, -45), 16, 16, s.camera);
  fr::ReferenceOptions o;
  o.path.spp = 2;
  o.max_spp = 4;
  const auto whole = fr::render_reference(ctx(), g, v, fc::Eye::Left, o);
  o.window.discs = {{v.pixel_to_dir({5, 6}), 20.0}};
  const auto part = fr::render_reference(ctx(), g, v, fc::Eye::Left, o);
  const auto in = fr::window_coverage(o.window, v, "window");
  glm::dvec3 mean(0);
  int n = 0;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i]) {
      EXPECT_EQ(part.image.pixels[i], whole.image.pixels[i]) << i;
      mean += glm::dvec3(part.image.pixels[i]);
      ++n;
    } else {
      EXPECT_EQ(part.image.pixels[i], glm::vec4(0)) << i;  // not traced, alpha 0
    }
  }
  ASSERT_GT(n, 10);
  ASSERT_LT(n, 200);
  EXPECT_EQ(part.spp, 4u);
  EXPECT_NEAR(part.mean_rgb.x, mean.x / n, 1e-6);
  EXPECT_NE(part.mean_rgb.x, whole.mean_rgb.x);
  EXPECT_GT(part.pixel_rel_error, 0.0);
  EXPECT_TRUE(std::isfinite(part.pixel_rel_error));
}

TEST(ReferenceCli, BadScenesAndArgumentsExitWithTwo) {
  // FOVEA_BINARY_DIR, else the build tree this test runs from (<build>/tests/renderer/).
  const char* bin = std::getenv("FOVEA_BINARY_DIR");
  const std::filesystem::path build =
      bin ? std::filesystem::path(bin) : std::filesystem::read_symlink("/proc/self/exe").parent_path() / "../..";
  const std::string fovea = (build / "tools/fovea").string();
  ASSERT_TRUE(std::filesystem::exists(fovea)) << fovea;
  const auto dir = std::filesystem::temp_directory_path() / ("fovea_refcli_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "bad.gltf") << "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"uri\": \"nope.bin\", \"byteLength\": 9}]}";
  auto status = [&](const std::string& args) {
    const int rc = std::system((fovea + " reference --display tiny --spp 1 " + args + " >/dev/null 2>&1").c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  };
  EXPECT_EQ(status("--scene " + (dir / "bad.gltf").string() + " --out " + (dir / "x.exr").string()), 2);
  EXPECT_EQ(status("--scene /usr/share/assimp/models/invalid/empty.obj --out " + (dir / "x.exr").string()), 2);
  EXPECT_EQ(status("--scene cornell --out " + (dir / "x.tiff").string()), 2);
  EXPECT_EQ(status("--scene cornell --spp=0 --out " + (dir / "x.exr").string()), 2);
  EXPECT_EQ(status("--scene cornell --eye middle --out " + (dir / "x.exr").string()), 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.exr"));
  EXPECT_EQ(status("--scene cornell --out " + (dir / "x.png").string()), 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "x.exr"));
  EXPECT_TRUE(std::filesystem::exists(dir / "x.png"));
  std::filesystem::remove_all(dir);
}
