// Progressive reference rendering, its stop criterion, EXR output, and the CLI's exit
// codes for bad scenes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <tinyexr.h>

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
