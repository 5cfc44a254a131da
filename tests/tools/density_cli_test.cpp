// `fovea density`: JSON equals the CPU model, PNG written atomically, bad input -> exit 2.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "fovea/core/density_report.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"

using namespace fovea;
using fovea::test::run_fovea;

namespace {

class DensityCli : public ::testing::TestWithParam<const char*> {};

TEST_P(DensityCli, JsonMatchesCpuModel) {
  const std::string dist = GetParam();
  const auto r = run_fovea("density --display small --eye right --gaze 0.3,0.6 --distribution " + dist + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = fovea::core::parse_json(r.out);

  const core::View view = core::load_display("small").view(core::Eye::Right);
  core::DistributionParams p;
  p.kind = core::parse_distribution(dist);
  auto d = core::make_distribution(view, p);
  d->set_frame(view.pixel_to_dir({0.3 * view.width(), 0.6 * view.height()}));
  const auto m = core::measure_density(*d);

  EXPECT_EQ(j["distribution"], dist);
  EXPECT_EQ(j["display"], "small");
  EXPECT_NEAR(j["gaze"]["x"].get<double>(), 0.3, 1e-9);
  EXPECT_NEAR(j["gaze"]["y"].get<double>(), 0.6, 1e-9);
  EXPECT_EQ(j["grid"]["columns"], m.columns);
  EXPECT_EQ(j["grid"]["rows"], m.rows);
  EXPECT_DOUBLE_EQ(j["grid"]["fill"].get<double>(), m.fill);
  EXPECT_EQ(j["samples_traced"], m.traced);
  EXPECT_EQ(j["samples_offscreen"], m.offscreen);
  EXPECT_DOUBLE_EQ(j["fovea_spp"].get<double>(), m.fovea_spp);
  ASSERT_EQ(j["bands"].size(), m.bands.size());
  for (size_t i = 0; i < m.bands.size(); ++i) {
    EXPECT_DOUBLE_EQ(j["bands"][i]["e_min"].get<double>(), m.bands[i].e_min);
    EXPECT_DOUBLE_EQ(j["bands"][i]["samples_per_deg2"].get<double>(), m.bands[i].samples_per_deg2);
    EXPECT_DOUBLE_EQ(j["bands"][i]["target_samples_per_deg2"].get<double>(), m.bands[i].target_samples_per_deg2);
  }
}

INSTANTIATE_TEST_SUITE_P(Kinds, DensityCli,
                         ::testing::Values("visual-polar", "paper-visual-polar", "cartesian", "cartesian-uniform",
                                           "linear-falloff", "log-polar"),
                         [](const auto& i) {
                           std::string n = i.param;
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

TEST(DensityCliOutput, WritesFigureAndDataAtomically) {
  const std::string dir = test::temp_dir("density");
  const std::string png = dir + "/heat.png";
  const auto r = run_fovea("density --display tiny --gaze 0,0 --out " + png);
  ASSERT_EQ(r.status, 0) << r.err;
  // The figure (matplotlib, PNG and SVG) and its data: the per-pixel map and what to mark.
  EXPECT_GT(core::read_png(png).width, 64);
  const std::string svg = test::read_text(dir + "/heat.svg");
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("samples per display pixel (log scale)"), std::string::npos) << "the colour bar has a title";
  const auto j = fovea::core::parse_json(test::read_text(dir + "/heat.json"));
  EXPECT_EQ(j["figure"], "density");
  EXPECT_EQ(j["array"], "heat.npy");
  const std::string npy = test::read_text(dir + "/heat.npy");
  ASSERT_GT(npy.size(), 128u);
  EXPECT_EQ(npy.substr(0, 6), "\x93NUMPY");
  EXPECT_NE(npy.find("'shape': (2, 72, 64)"), std::string::npos) << npy.substr(0, 128);
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 4) << "PNG, SVG, JSON and NPY; no temporary files left behind";
  // Unwritable destination (a file where its directory should be): exit 2 naming it, no
  // partial file. (A missing directory is created: HostileInputs.MissingOutputDirectoriesAreCreated.)
  const auto bad = run_fovea("density --display tiny --out " + png + "/heat.png");
  EXPECT_EQ(bad.status, 2) << bad.err;
  EXPECT_NE(bad.err.find(png), std::string::npos) << bad.err;
  entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 4) << "nothing written beside the figure";
  std::filesystem::remove_all(dir);
}

TEST(DensityCliOutput, ExtremeGazesAreReported) {
  const auto off = run_fovea("density --display tiny --gaze 2,-1 --json");
  ASSERT_EQ(off.status, 0) << off.err;
  EXPECT_TRUE(fovea::core::parse_json(off.out)["gaze"]["clamped"].get<bool>());
  const auto nan = run_fovea("density --display tiny --gaze-dir nan,0,-1 --json");
  ASSERT_EQ(nan.status, 0) << nan.err;
  EXPECT_TRUE(fovea::core::parse_json(nan.out)["gaze"]["fallback"].get<bool>());
}

TEST(DensityCliErrors, BadInputExitsWithTwo) {
  for (const char* args : {"density --distribution polar", "density --budget 0", "density --budget 1.5",
                           "density --budget abc", "density --gamma 3", "density --gaze 0.5",
                           "density --gaze a,b", "density --display nonexistent-preset", "density --eye middle",
                           "density --bogus", "density stray", "density --gaze 0.5,0.5 --gaze-dir 0,0,-1"}) {
    const auto r = run_fovea(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_FALSE(r.err.empty()) << args;
  }
  const auto help = run_fovea("density --help");
  EXPECT_EQ(help.status, 0);
  for (const char* opt : {"--display", "--eye", "--gaze", "--gaze-dir", "--distribution", "--budget", "--margin",
                          "--gamma", "--cap", "--aniso", "--out", "--json"})
    EXPECT_NE(help.out.find(opt), std::string::npos) << opt;
}

TEST(DensityCliErrors, MalformedDisplayFileNamesTheField) {
  const std::string dir = test::temp_dir("display");
  {
    std::ofstream(dir + "/bad.json") << R"({"name": "x", "width": 100, "height": -3, "fov_deg": {"left": -40, "right": 40, "up": 40, "down": -40}})";
    std::ofstream(dir + "/broken.json") << R"({"name": "x", "width": 100,)";
  }
  const auto r = run_fovea("density --display " + dir + "/bad.json");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("height"), std::string::npos) << r.err;
  const auto b = run_fovea("density --display " + dir + "/broken.json");
  EXPECT_EQ(b.status, 2);
  EXPECT_NE(b.err.find("broken.json"), std::string::npos) << b.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
