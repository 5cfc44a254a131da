// `fovea latency` end to end on the tiny display: the summary, records and plots of a
// simulation with a fixed render time, the same analysis from the written records, and
// bad input -> exit 2 naming it.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"

#include "fovea/core/json.hpp"

using fovea::test::run_fovea;

namespace {

namespace fs = std::filesystem;

TEST(LatencyCli, SimulationThenItsRecords) {
  const std::string dir = fovea::test::temp_dir("latency");
  const auto r = run_fovea("latency --display tiny --seconds 0.3 --render-time 8ms --inject-latency 0,60ms "
                           "--quality-frames 0 --quiet --out " + dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = fovea::core::parse_json(r.out);
  EXPECT_EQ(j["mode"], "simulation");
  EXPECT_EQ(j["render_cost"]["source"], "fixed");
  EXPECT_EQ(j["render_cost"]["ms"]["median"].get<double>(), 8.0);
  // fove0: 15 ms delay plus up to 2 ms jitter.
  const double delay = j["tracker_delay_ms"]["median"].get<double>();
  EXPECT_GE(delay, 15.0);
  EXPECT_LE(delay, 17.0);
  EXPECT_GT(j["gaze_to_photon_ms"]["median"].get<double>(), delay + 8.0);
  // The same frames with each compensation mode (--predict), the first without.
  ASSERT_EQ(j["compensation"].size(), 3u);
  EXPECT_EQ(j["compensation"][0]["predict"], "none");
  EXPECT_EQ(j["compensation"][2]["predict"], "landing");
  // The main run is the one without: the same panel errors.
  EXPECT_EQ(j["compensation"][0]["foveal_error_deg"]["median"], j["foveal_error_deg"]["median"]);
  ASSERT_EQ(j["sweep"].size(), 2u);
  EXPECT_EQ(j["sweep"][1]["inject_ms"].get<double>(), 60.0);
  EXPECT_GT(j["sweep"][1]["gaze_to_photon_median_ms"].get<double>(),
            j["sweep"][0]["gaze_to_photon_median_ms"].get<double>() + 55.0);
  for (const char* f : {"records.jsonl", "summary.json", "latency.png", "stages.png", "foveal_error.png", "sweep_error.png"})
    EXPECT_TRUE(fs::exists(fs::path(dir) / f)) << f;
  EXPECT_FALSE(fs::exists(fs::path(dir) / "records.jsonl.tmp"));

  const std::string again = fovea::test::temp_dir("latency_records");
  const auto rec = run_fovea("latency --records " + dir + "/records.jsonl --out " + again);
  ASSERT_EQ(rec.status, 0) << rec.err;
  const auto k = fovea::core::parse_json(rec.out);
  EXPECT_EQ(k["mode"], "records");
  EXPECT_EQ(k["clock"], "virtual");
  EXPECT_EQ(k["frames"], j["frames"]);
  EXPECT_EQ(k["tracker_delay_ms"], j["tracker_delay_ms"]);
  EXPECT_EQ(k["gaze_to_photon_ms"], j["gaze_to_photon_ms"]);
  EXPECT_TRUE(k.contains("foveal_error_deg"));  // the records carry the truth
  EXPECT_TRUE(fs::exists(fs::path(again) / "latency.png"));
  fs::remove_all(dir);
  fs::remove_all(again);
}

// Where the user looks after a saccade, a stale fovea leaves the periphery's sparse samples:
// with strong foveation the quality within a few degrees of the true gaze at photon time is
// lower with 100 ms injected than with none. A 128x144 panel with fove0's optics, 0.05 of its
// pixels traced; the same frames and seeds at both points, so only the gaze differs. The
// main run is not rendered (a fixed render time): the sweep renders what it scores.
TEST(LatencyCli, QualityWhereTheUserLooksFallsWithInjectedLatency) {
  const std::string dir = fovea::test::temp_dir("latency_quality");
  std::ofstream(dir + "/panel.json") << R"({"name": "panel", "width": 128, "height": 144, "refresh_hz": 70,
    "fov_deg": {"left": -50, "right": 50, "up": 53.28, "down": -53.28}})";
  const auto r = run_fovea("latency --display " + dir + "/panel.json --seconds 1.2 --render-time 10ms --budget 0.05 "
                           "--gaze 'synthetic:3?task=search&rate=1000&noise=0&dropouts=0' --inject-latency 0,50,100 "
                           "--quality-at 0,100 --quality-frames 4 --quality-radius 4 --reference-spp 16 "
                           "--reference-cache off --no-main-render --quiet --out " + dir + "/out");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = fovea::core::parse_json(r.out);
  ASSERT_EQ(j["sweep"].size(), 3u);
  EXPECT_FALSE(j["sweep"][1].contains("fovea_quality"));  // not in --quality-at
  const auto& q0 = j["sweep"][0]["fovea_quality"];
  const auto& q100 = j["sweep"][2]["fovea_quality"];
  ASSERT_GE(q0["saccades"].get<int>(), 1);
  EXPECT_EQ(q0["frames"], q100["frames"]);
  EXPECT_GT(q0["psnr_db"].get<double>(), q100["psnr_db"].get<double>());
  EXPECT_LT(q0["hdr_flip"].get<double>(), q100["hdr_flip"].get<double>());
  EXPECT_EQ(j["config"]["budget"].get<double>(), 0.05);
  EXPECT_FALSE(j["render_cost"]["main_run_rendered"].get<bool>());
  EXPECT_EQ(j["render_cost"]["measured_ms"]["n"], 0);
  for (const char* f : {"sweep_quality.png", "sweep_flip.png"}) EXPECT_TRUE(fs::exists(fs::path(dir) / "out" / f)) << f;
  fs::remove_all(dir);
}

TEST(LatencyCli, BadInputExitsTwoNamingIt) {
  const std::string dir = fovea::test::temp_dir("latency_bad");
  const std::string bad = dir + "/bad.jsonl";
  std::ofstream(bad) << "{\"schema\":\"fovea-timing\",\"version\":1,\"source\":\"runtime\",\"clock\":\"monotonic\",\"frame\":0}\n"
                     << "{\"schema\":\"fovea-timing\",\"version\":1,\"source\":\"runtime\",\"clock\":\"monotonic\"}\n";
  const struct {
    std::string args, expect;
  } cases[] = {
      {"latency --records " + bad, "bad.jsonl:2"},
      {"latency --records " + dir + "/missing.jsonl", "missing.jsonl"},
      {"latency --records " + bad + " --scene cornell", "--scene"},
      {"latency --tracker-delay 5parsecs", "--tracker-delay"},
      {"latency --inject-latency 0,2s", "--inject-latency"},
      {"latency --predict sideways", "--predict"},
      {"latency --scan-out diagonal", "diagonal"},
      {"latency --gaze 'synthetic:1?tracker=fove0'", "--tracker-delay"},
      {"latency --inject-latency 0,50 --quality-at 25", "--quality-at"},
      {"latency --quality-radius 0", "--quality-radius"},
      {"latency --budget 2", "--budget"},
      {"latency --no-main-render", "--no-main-render"},
  };
  for (const auto& c : cases) {
    const auto r = run_fovea(c.args + " --out " + dir + "/out");
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << "\n" << r.err;
  }
  fs::remove_all(dir);
}

}  // namespace
