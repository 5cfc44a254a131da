// `fovea gaze` and `fovea xr-info` as a researcher's scripts use them: event lists and data
// quality, replay URIs with keys, kept time base and messages, bounded plots, and the fuzz
// findings' inputs giving exit 2 with a message naming the input (never a crash).
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"

#include "fovea/core/json.hpp"

using fovea::test::read_text;
using fovea::test::run_fovea;
using fovea::test::temp_dir;

namespace {

std::string write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}
std::string shipped(const std::string& name) {
  const char* s = std::getenv("FOVEA_SOURCE_DIR");
  return std::string(s ? s : ".") + "/data/gaze/" + name;
}

}  // namespace

TEST(GazeCli, InfoListsEventsAndDataQualityAndTakesUriKeys) {
  const auto r = run_fovea("gaze info --events 'replay:" + shipped("default.csv") + "?filters=ivt'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = fovea::core::parse_json(r.out);
  ASSERT_GT(j["events"].size(), 10u);
  std::size_t saccades = 0;
  std::int64_t last = -1;
  for (const auto& e : j["events"]) {
    EXPECT_LE(e["start_ns"].get<std::int64_t>(), e["end_ns"].get<std::int64_t>());
    if (e["type"] == "saccade") {
      ++saccades;
      EXPECT_GT(e["amplitude_deg"].get<double>(), 0);
      EXPECT_GT(e["start_ns"].get<std::int64_t>(), last);
      last = e["start_ns"].get<std::int64_t>();
    }
  }
  EXPECT_EQ(saccades, j["saccades"].get<std::size_t>());
  EXPECT_GT(j["data_quality"]["rms_s2s_deg"].get<double>(), 0);
  EXPECT_GT(j["data_quality"]["std_deg"].get<double>(), 0);
  EXPECT_GE(j["data_quality"]["data_loss"].get<double>(), 0);

  const auto bad = run_fovea("gaze info 'replay:" + shipped("default.csv") + "?filters=median'");
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.err.find("no such file"), std::string::npos) << bad.err;
}

TEST(GazeCli, ConvertKeepsTheTimeBaseAndTheMessages) {
  const std::string dir = temp_dir("gaze-convert");
  const std::string asc = write(dir + "/rec.asc",
                                "** CONVERTED FROM rec.edf\nMSG\t5000 DISPLAY_COORDS 0 0 1919 1079\nMSG\t5001 TRIALID 7\n"
                                "SAMPLES\tGAZE\tLEFT\tRATE\t500.00\n5002\t960.0\t540.0\t1000.0\n5004\t961.0\t540.0\t1000.0\n"
                                "MSG\t5004 target \"A\", onset\n5006\t961.0\t541.0\t1000.0\n");
  const auto r = run_fovea("gaze convert " + asc + " " + dir + "/out.csv --screen 1920x1080@531x299mm@700mm");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto side = fovea::core::parse_json(read_text(dir + "/out.csv.json"));
  EXPECT_EQ(side["time_base"]["t0_device_time_ns"], 5'002'000'000);
  EXPECT_NEAR(side["screen"]["hfov_deg"].get<double>(), 41.55, 0.01);
  EXPECT_EQ(read_text(dir + "/out.csv.events.csv"),
            "t_ns,device_time_ns,kind,text\n"
            "-2000000,5000000000,msg,\"DISPLAY_COORDS 0 0 1919 1079\"\n"
            "-1000000,5001000000,msg,\"TRIALID 7\"\n"
            "2000000,5004000000,msg,\"target \"\"A\"\", onset\"\n");
  std::filesystem::remove_all(dir);
}

TEST(GazeCli, PlotIsBoundedAndWindowed) {
  const std::string dir = temp_dir("gaze-plot");
  // Fuzz finding 5: a valid two-row file spanning 9e18 ns drew one grid line per second.
  const std::string span = write(dir + "/span.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n0,C,0,0,-1,1,1\n"
                                                     "9000000000000000000,C,0.1,0,-1,1,1\n");
  const auto r = run_fovea("gaze plot " + span + " " + dir + "/span.png");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/span.png"));
  const auto w = run_fovea("gaze plot " + shipped("default.csv") + " " + dir + "/w.png --from 1 --to 2.5 --width 600");
  ASSERT_EQ(w.status, 0) << w.err;
  const auto empty = run_fovea("gaze plot " + shipped("default.csv") + " " + dir + "/e.png --from 100 --to 200");
  EXPECT_EQ(empty.status, 2);
  EXPECT_NE(empty.err.find("--from/--to"), std::string::npos) << empty.err;
  EXPECT_EQ(run_fovea("gaze plot " + shipped("default.csv") + " " + dir + "/x.png --from 3 --to 1").status, 2);
  std::filesystem::remove_all(dir);
}

TEST(GazeCli, FuzzFindingsGiveExitTwoOrSaneOutput) {
  const std::string dir = temp_dir("gaze-fuzz");
  // (1) a sidecar nested 60,000 levels deep.
  const std::string deep = write(dir + "/deep.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n0,C,0,0,-1,1,1\n");
  write(deep + ".json", std::string(60000, '[') + std::string(60000, ']'));
  for (const char* sub : {"info ", "plot "}) {
    const auto r = run_fovea(std::string("gaze ") + sub + deep + (std::string(sub) == "plot " ? " " + dir + "/p.png" : ""));
    EXPECT_EQ(r.status, 2) << sub << r.err;
    EXPECT_NE(r.err.find("deep.csv.json"), std::string::npos) << r.err;
  }
  // (6) extreme timestamps: the duration never goes negative.
  const std::string ext = write(dir + "/ext.csv", "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n-9000000000000000000,C,0,0,-1,1,1\n"
                                                  "9000000000000000000,C,0,0,-1,1,1\n");
  const auto e = run_fovea("gaze info " + ext);
  ASSERT_EQ(e.status, 0) << e.err;
  const auto ej = fovea::core::parse_json(e.out);
  EXPECT_GE(ej["duration_s"].get<double>(), 0);
  EXPECT_EQ(ej["dropped"]["time_overflow"], 1);
  // (7) one timestamp byte of the shipped capture changed to 2^62 µs: no negative t_ns.
  std::string cap = read_text(shipped("hid-ms.hidcap"));
  const auto at = cap.find(" 10 ", cap.find("\ninput ", cap.find("\ninput ") + 1));
  cap.replace(at + 4, 23, "00 00 00 00 00 00 00 40");
  const std::string capf = write(dir + "/ts.hidcap", cap);
  const auto c = run_fovea("gaze convert " + capf + " " + dir + "/cap.csv");
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(c.err.find("time_overflow: 1"), std::string::npos) << c.err;
  EXPECT_EQ(read_text(dir + "/cap.csv").find("\n-"), std::string::npos);
  // A bad geometry is named wherever it is given.
  const auto sc = run_fovea("render --display tiny --frames 1 --screen 12 --out " + dir + "/r");
  EXPECT_EQ(sc.status, 2);
  EXPECT_NE(sc.err.find("--screen"), std::string::npos) << sc.err;
  const auto su = run_fovea("gaze info '" + shipped("default.csv") + "?screen=1x1@200x1'");
  EXPECT_EQ(su.status, 2);
  EXPECT_NE(su.err.find("screen"), std::string::npos) << su.err;
  // An unrelated JSON file is not read as Tobii gaze.
  const auto j = run_fovea("gaze info " + write(dir + "/package.json", "{\"name\": \"x\"}\n"));
  EXPECT_EQ(j.status, 2);
  EXPECT_NE(j.err.find("not Tobii Glasses 3"), std::string::npos) << j.err;
  std::filesystem::remove_all(dir);
}

TEST(XrInfoCli, ExitsNonZeroWhenNoRuntimeLoads) {
  const std::string dir = temp_dir("xr-info");
  const std::string manifest = write(dir + "/runtime.json", R"({"file_format_version": "1.0.0",
    "runtime": {"name": "missing", "library_path": "./no_such_runtime.so"}})");
  const auto r = run_fovea("xr-info --json --runtime-json " + manifest);
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("no OpenXR runtime loads"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}

// `fovea render` replays through a GazeSource; the reader's notes still reach the user.
TEST(GazeCli, RenderWarnsAboutGazeOffTheDisplay) {
  const std::string dir = temp_dir("gaze-render");
  const std::string asc = write(dir + "/off.asc", "** x\nMSG\t999 GAZE_COORDS 0.00 0.00 1919.00 1079.00\n"
                                                  "SAMPLES\tGAZE\tLEFT\tRATE\t500.00\n1000\t2500.0\t540.0\t1000.0\n"
                                                  "1002\t961.0\t540.0\t1000.0\n");
  const auto r = run_fovea("render --display tiny --scene cornell --frames 1 --png-every 0 --quiet --gaze '" + asc +
                           "?screen=1920x1080@95x63' --out " + dir + "/out");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: " + asc + ": 1 of 2 samples lie outside the display (1920x1080 px)"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}
