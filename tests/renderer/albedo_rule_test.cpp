// Bounce count and Russian roulette from the scene's albedo (albedo_stats,
// albedo_path_config): the rule itself, the white furnace's analytic value under it, the
// same image as the fixed unlimited setting within noise, and `fovea reference` using it
// unless --bounces / --rr-start are given.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

#include "fovea/renderer/path_tracer.hpp"
#include "fovea/renderer/procedural.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pt_helpers.hpp"

namespace fr = fovea::renderer;
namespace fc = fovea::core;
using fovea::test::mean_rgb;
using fovea::test::trace_grid;

TEST(AlbedoRule, StatisticsFollowTheMaterials) {
  const fr::AlbedoStats f = fr::albedo_stats(fr::make_furnace(0.5f));
  EXPECT_NEAR(f.mean, 0.5f, 1e-6f);
  EXPECT_NEAR(f.max, 0.5f, 1e-6f);
  // A white metal reflects everything; a dielectric adds F0 over its diffuse base.
  fr::Scene s = fr::make_furnace(0.5f);
  s.materials[0].metallic = 1.0f;
  s.materials[0].base_color = glm::vec3(1.0f);
  EXPECT_NEAR(fr::albedo_stats(s).max, 1.0f, 1e-6f);
  s.materials[0].metallic = 0.0f;
  s.materials[0].base_color = glm::vec3(0.2f, 0.4f, 0.1f);
  s.materials[0].specular = 0.04f;
  EXPECT_NEAR(fr::albedo_stats(s).max, 0.04f + 0.96f * 0.4f, 1e-6f);
  // Textures: the mean texel for the mean, the brightest for the max (sRGB decoded).
  s.materials[0].specular = 0.0f;
  s.materials[0].base_color = glm::vec3(1.0f);
  s.materials[0].base_color_texture = 0;
  s.textures.push_back({"half", 2, 1, {0, 0, 0, 255, 255, 255, 255, 255}});
  const fr::AlbedoStats t = fr::albedo_stats(s);
  EXPECT_NEAR(t.mean, 0.5f, 1e-6f);
  EXPECT_NEAR(t.max, 1.0f, 1e-6f);
  // Area weighting: cornell's walls (0.7–0.75 albedo white, red, green) dominate.
  const fr::AlbedoStats c = fr::albedo_stats(fr::load_scene("cornell"));
  EXPECT_GT(c.mean, 0.3f);
  EXPECT_LT(c.mean, c.max);
  EXPECT_LE(c.max, 1.0f);
}

TEST(AlbedoRule, LowAlbedoScenesGetFewerBounces) {
  // max^n <= 1e-3: 0.09 -> 3, 0.5 -> 10 (0.5^10 = 9.8e-4), 0.9 -> 66; white: Russian roulette only.
  EXPECT_EQ(fr::albedo_path_config({0.09f, 0.09f}).max_bounces, 3);
  EXPECT_EQ(fr::albedo_path_config({0.5f, 0.5f}).max_bounces, 10);
  EXPECT_EQ(fr::albedo_path_config({0.5f, 0.9f}).max_bounces, 66);
  EXPECT_EQ(fr::albedo_path_config({0.9f, 1.0f}).max_bounces, -1);
  // mean^k <= 0.5: 0.5 -> 1, 0.9 -> 7 (0.9^7 = 0.48), white: the latest start.
  EXPECT_EQ(fr::albedo_path_config({0.5f, 0.5f}).rr_start, 1u);
  EXPECT_EQ(fr::albedo_path_config({0.9f, 0.9f}).rr_start, 7u);
  EXPECT_EQ(fr::albedo_path_config({1.0f, 1.0f}).rr_start, std::uint32_t(fr::kAlbedoRouletteLatest));
  EXPECT_EQ(fr::albedo_path_config({0.0f, 0.0f}).max_bounces, 1);
  // spp and jitter come from the base configuration.
  fr::PathConfig base;
  base.spp = 7;
  base.jitter = true;
  const fr::PathConfig c = fr::albedo_path_config({0.5f, 0.5f}, base);
  EXPECT_EQ(c.spp, 7u);
  EXPECT_TRUE(c.jitter);
  // Darker furnaces, fewer bounces.
  EXPECT_LT(fr::albedo_path_config(fr::albedo_stats(fr::make_furnace(0.2f))).max_bounces,
            fr::albedo_path_config(fr::albedo_stats(fr::make_furnace(0.5f))).max_bounces);
}

class AlbedoRuleGpu : public fovea::test::GpuTest {};

// 10 bounces truncate Σ 0.5^k at k = 11: 2 − 0.5^11 = 1.9995, within the 1% tolerance.
TEST_F(AlbedoRuleGpu, WhiteFurnaceConvergesToItsAnalyticValue) {
  const fr::Scene s = fr::load_scene("furnace");
  fr::GpuScene g(ctx(), s);
  const fr::PathConfig c = fr::albedo_path_config(fr::albedo_stats(s), {256, 0, 0, false});
  ASSERT_EQ(c.max_bounces, 10);
  const fc::View v(fc::Fov::from_degrees(-50, 50, 50, -50), 4, 4);
  const glm::dvec3 m = mean_rgb(trace_grid(ctx(), g, fr::cartesian_grid(v), v, fc::Eye::Left, c, 16).radiance);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(m[i], 2.0, 0.02) << "channel " << i;
}

// The rule against the fixed reference setting (unlimited, Russian roulette from bounce 3)
// on cornell: the same mean radiance within noise, and the time each took.
TEST_F(AlbedoRuleGpu, CornellMatchesTheFixedSettingWithinNoise) {
  const fr::Scene s = fr::load_scene("cornell");
  fr::GpuScene g(ctx(), s);
  const fc::View v(fc::Fov::from_degrees(-40, 40, 40, -40), 16, 16, s.camera);
  const auto grid = fr::cartesian_grid(v);
  const fr::PathConfig fixed{64, -1, 3, true};
  const fr::PathConfig rule = fr::albedo_path_config(fr::albedo_stats(s), {64, 0, 0, true});
  auto timed = [&](const fr::PathConfig& c, glm::dvec3& mean) {
    const auto t0 = std::chrono::steady_clock::now();
    mean = mean_rgb(trace_grid(ctx(), g, grid, v, fc::Eye::Left, c, 8).radiance);
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  glm::dvec3 a, b;
  const double ta = timed(fixed, a), tb = timed(rule, b);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(b[i] / a[i], 1.0, 0.02) << "channel " << i;
  std::printf("cornell 16x16 @ 512 spp: fixed (-1, rr 3) %.4f %.4f %.4f in %.2f s; rule (%d, rr %u) %.4f %.4f %.4f in %.2f s\n",
              a.x, a.y, a.z, ta, rule.max_bounces, rule.rr_start, b.x, b.y, b.z, tb);
}

#ifdef FOVEA_EXE
TEST(AlbedoRuleCli, ReferenceUsesTheRuleUnlessBouncesAreGiven) {
  const auto dir = std::filesystem::temp_directory_path() / ("fovea_albedo_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto run = [&](const std::string& args, std::string& output) {
    const std::string cmd = std::string(FOVEA_EXE) + " reference --display tiny --spp 1 --scene furnace " +
                            "--reference-cache off --quiet --out " + (dir / "x.exr").string() + " " + args + " >" +
                            (dir / "log").string() + " 2>&1";
    const int rc = std::system(cmd.c_str());
    std::ifstream log(dir / "log");
    output.assign(std::istreambuf_iterator<char>(log), std::istreambuf_iterator<char>());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  };
  std::string out;
  EXPECT_EQ(run("", out), 0);
  EXPECT_NE(out.find("\"bounces\":10"), std::string::npos) << out;
  EXPECT_NE(out.find("\"rr_start\":1"), std::string::npos) << out;
  EXPECT_EQ(run("--bounces 2 --rr-start 5", out), 0);
  EXPECT_NE(out.find("\"bounces\":2"), std::string::npos) << out;
  EXPECT_NE(out.find("\"rr_start\":5"), std::string::npos) << out;
  EXPECT_EQ(run("--bounces many", out), 2);
  std::filesystem::remove_all(dir);
}
#endif
