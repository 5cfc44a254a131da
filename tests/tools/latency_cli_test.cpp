// `fovea latency` end to end on the tiny display: the summary, records and plots of a
// simulation with a fixed render time, the same analysis from the written records, and
// bad input -> exit 2 naming it.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"

using fovea::test::run_fovea;

namespace {

namespace fs = std::filesystem;

TEST(LatencyCli, SimulationThenItsRecords) {
  const std::string dir = fovea::test::temp_dir("latency");
  const auto r = run_fovea("latency --display tiny --seconds 0.3 --render-time 8ms --inject-latency 0,60ms "
                           "--quality-frames 0 --quiet --out " + dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
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
  const auto k = nlohmann::json::parse(rec.out);
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
  };
  for (const auto& c : cases) {
    const auto r = run_fovea(c.args + " --out " + dir + "/out");
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << "\n" << r.err;
  }
  fs::remove_all(dir);
}

}  // namespace
