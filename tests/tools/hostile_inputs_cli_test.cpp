// Inputs a new user gets wrong, answered by the command line: output paths that cannot be
// written (exit 2 before any work), missing output directories (created), a gaze the grid
// cannot use (rendered as the report says, with a warning), statistics of nothing (null, not
// 0), a reference too short to estimate its error (null and a warning), and default outputs
// under out/ rather than the current directory.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"

#include "fovea/core/json.hpp"

namespace fs = std::filesystem;
using fovea::test::run_fovea;

namespace hostile_inputs {

nlohmann::json json_file(const std::string& path) {
  std::ifstream in(path);
  return fovea::core::parse_json(in);
}

// A recording in the project's CSV whose every sample looks along `dir`.
std::string constant_gaze_csv(const std::string& dir, const std::string& xyz) {
  const std::string path = dir + "/gaze.csv";
  std::ofstream f(path);
  f << "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n";
  for (int i = 0; i < 60; ++i) f << i * 8333333L << ",combined," << xyz << ",0.95,1\n";
  return path;
}

TEST(HostileInputs, OutNamingAnExistingFileIsRefusedBeforeRendering) {
  const std::string dir = fovea::test::temp_dir("out-file");
  const std::string file = dir + "/existing";
  std::ofstream(file) << "keep me";
  const auto r = run_fovea("render --display tiny --frames 1 --quiet --out " + file);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--out \"" + file + "\": exists and is not a directory"), std::string::npos) << r.err;
  EXPECT_EQ(fovea::test::read_text(file), "keep me");
  // A file where a parent directory should be: every command names the option and the path.
  const auto lens = run_fovea("lens --display tiny --out " + file + "/lens.png");
  EXPECT_EQ(lens.status, 2) << lens.err;
  EXPECT_NE(lens.err.find("--out \"" + file + "\""), std::string::npos) << lens.err;
  const auto convert = run_fovea("gaze convert synthetic:1?seconds=1 " + file + "/g.csv");
  EXPECT_EQ(convert.status, 2) << convert.err;
  EXPECT_NE(convert.err.find("not a directory"), std::string::npos) << convert.err;
  fs::remove_all(dir);
}

TEST(HostileInputs, MissingOutputDirectoriesAreCreated) {
  const std::string dir = fovea::test::temp_dir("out-missing");
  const std::string csv = dir + "/a/b/g.csv";
  const auto convert = run_fovea("gaze convert synthetic:1?seconds=1 " + csv);
  ASSERT_EQ(convert.status, 0) << convert.err;
  EXPECT_TRUE(fs::is_regular_file(csv));
  const auto plot = run_fovea("gaze plot " + csv + " " + dir + "/c/d/plot.png");
  EXPECT_EQ(plot.status, 0) << plot.err;
  const auto lens = run_fovea("lens --display tiny --out " + dir + "/e/lens.png");
  ASSERT_EQ(lens.status, 0) << lens.err;
  EXPECT_TRUE(fs::is_regular_file(dir + "/e/lens.png"));
  fs::remove_all(dir);
}

TEST(HostileInputs, LensWritesItsDefaultPictureUnderOut) {
  const std::string dir = fovea::test::temp_dir("lens-default");
  const std::string cmd = "cd " + dir + " && " + std::string(FOVEA_EXE) + " lens --display tiny >/dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_TRUE(fs::is_regular_file(dir + "/out/lens/lens-tiny.png"));
  EXPECT_FALSE(fs::exists(dir + "/lens-tiny.png"));
  fs::remove_all(dir);
}

TEST(HostileInputs, GazeBehindTheViewerIsReportedAsRendered) {
  const std::string dir = fovea::test::temp_dir("behind");
  const std::string gaze = constant_gaze_csv(dir, "0,0,1");
  const auto r = run_fovea("render --display tiny --scene cornell --frames 2 --quiet --gaze " + gaze + " --out " +
                           dir + "/r");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: --gaze " + gaze + ": the left eye's gaze was unusable"), std::string::npos) << r.err;
  const nlohmann::json report = json_file(dir + "/r/report.json");
  std::ifstream frames(dir + "/r/frames.jsonl");
  std::string line;
  int n = 0;
  while (std::getline(frames, line)) {
    const nlohmann::json f = fovea::core::parse_json(line);
    // The sample as measured stays in "gaze"; what the grid used is what report.json says.
    EXPECT_EQ(f["gaze"]["combined"]["dir"][2].get<double>(), 1.0);
    for (const char* eye : {"left", "right"})
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(f["used_gaze"][eye][k].get<double>(), report["summary"][eye]["gaze"][k].get<double>(), 1e-12)
            << eye << "[" << k << "]";
    EXPECT_LT(f["used_gaze"]["left"][2].get<double>(), 0.0);
    ++n;
  }
  EXPECT_EQ(n, 2);
  fs::remove_all(dir);
}

TEST(HostileInputs, FlickerWithoutStillFramesIsNullWithAReason) {
  const std::string dir = fovea::test::temp_dir("flicker");
  // synthetic:1 moves the gaze from frame to frame.
  const auto r = run_fovea("render --display tiny --scene cornell --frames 2 --quiet --gaze synthetic:1?task=search "
                           "--out " + dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json s = json_file(dir + "/report.json")["summary"]["left"];
  ASSERT_TRUE(s.contains("flicker"));
  if (s["flicker_frames"].get<int>() < 2) {
    EXPECT_TRUE(s["flicker"].is_null());
    EXPECT_TRUE(s["flicker_note"].is_string());
  } else {
    ADD_FAILURE() << "the synthetic gaze held still: the test needs a moving gaze";
  }
  const auto help = run_fovea("render --help");
  EXPECT_EQ(help.out.find("Always: temporal_error and,"), std::string::npos);
  EXPECT_NE(help.out.find("flicker_note"), std::string::npos);
  fs::remove_all(dir);
}

TEST(HostileInputs, LatencyStatisticsOfNoSamplesAreNull) {
  const std::string dir = fovea::test::temp_dir("latency-null");
  // A render's timing records carry no vsync or photon time: no gaze-to-photon latency.
  const auto r = run_fovea("render --display tiny --scene cornell --frames 2 --quiet --png-every 0 --out " + dir + "/r");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto l = run_fovea("latency --records " + dir + "/r/frame_times.jsonl --out " + dir + "/l");
  ASSERT_EQ(l.status, 0) << l.err;
  const nlohmann::json s = json_file(dir + "/l/summary.json");
  EXPECT_EQ(s["gaze_to_photon_ms"]["n"], 0);
  for (const char* k : {"median", "p95", "p99", "max"}) EXPECT_TRUE(s["gaze_to_photon_ms"][k].is_null()) << k;
  EXPECT_GT(s["stages"]["gpu_ms"]["total"]["n"].get<int>(), 0);
  EXPECT_TRUE(s["stages"]["gpu_ms"]["total"]["median"].is_number());
  fs::remove_all(dir);
}

TEST(HostileInputs, AReferenceOfOneBatchHasNoErrorEstimate) {
  const std::string dir = fovea::test::temp_dir("ref-one-batch");
  const auto one = run_fovea("reference --display tiny --scene cornell --spp 4 --batch 4 --reference-cache off "
                             "--quiet --out " + dir + "/one.exr");
  ASSERT_EQ(one.status, 0) << one.err;
  const nlohmann::json j = fovea::core::parse_json(one.out);
  EXPECT_TRUE(j["rel_error"].is_null()) << one.out;
  EXPECT_TRUE(j["pixel_rel_error"].is_null()) << one.out;
  EXPECT_NE(one.err.find("single batch"), std::string::npos) << one.err;
  // Its description reads back (a render scoring against it takes it).
  EXPECT_TRUE(json_file(dir + "/one.json")["rel_error"].is_null());
  const auto two = run_fovea("reference --display tiny --scene cornell --spp 8 --batch 4 --reference-cache off "
                             "--quiet --out " + dir + "/two.exr");
  ASSERT_EQ(two.status, 0) << two.err;
  const nlohmann::json k = fovea::core::parse_json(two.out);
  EXPECT_GT(k["rel_error"].get<double>(), 0.0);
  EXPECT_EQ(two.err.find("single batch"), std::string::npos) << two.err;
  fs::remove_all(dir);
}

TEST(HostileInputs, BudgetRefusalsNameTheDisplayFile) {
  const std::string dir = fovea::test::temp_dir("wide-display");
  // The small preset widened to +-85 degrees: linear fall-off cannot go below its floor.
  const std::string file = dir + "/wide.json";
  std::ofstream(file) << R"({"name": "wide", "width": 320, "height": 360, "refresh_hz": 70, "ipd_m": 0.063,
    "fov_deg": {"left": -85, "right": 85, "up": 53.28, "down": -53.28}})";
  for (const std::string& cmd : {"render --frames 1 --quiet --out " + dir + "/r", std::string("density --json")}) {
    const auto r = run_fovea(cmd + " --distribution linear-falloff --budget 0.05 --display " + file);
    EXPECT_EQ(r.status, 2) << cmd << ": " << r.err;
    EXPECT_NE(r.err.find("display " + file + ": budget: linear-falloff reaches no less than"), std::string::npos)
        << cmd << ": " << r.err;
  }
  fs::remove_all(dir);
}

TEST(HostileInputs, GazeToolsOpenHidCapturesLikeEveryRecording) {
  const char* source = std::getenv("FOVEA_SOURCE_DIR");
  const std::string capture = std::string(source ? source : ".") + "/data/gaze/hid-ms.hidcap";
  for (const std::string& uri : {capture, "hid-capture:" + capture + "?speed=2"}) {
    const auto r = run_fovea("gaze info '" + uri + "'");
    ASSERT_EQ(r.status, 0) << uri << ": " << r.err;
    EXPECT_EQ(fovea::core::parse_json(r.out)["format"], "hid-capture") << uri;
  }
}

}  // namespace hostile_inputs
