// Sweeps of `fovea latency` jobs: plan expansion (counts, stable ids, argv), the summary's
// metrics read by key name, and the report's latency-against-quality plots, CSV columns and
// per-scene sections on a synthetic result set.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>

#include "cli.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"
#include "sweep/plan.hpp"
#include "sweep/report.hpp"

namespace fovea::sweep {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

CommandOptions command_options() {
  return {{"render", {{"scene", true}, {"display", true}, {"distribution", true}, {"budget", true}, {"out", true}, {"quiet", false}}},
          {"latency", {{"scene", true}, {"display", true}, {"tracker-delay", true}, {"predict", true}, {"seconds", true},
                       {"inject-latency", true}, {"out", true}, {"quiet", false}}}};
}

json latency_part() {
  return fovea::core::parse_json(R"({"command": "latency", "scenes": "default", "displays": "tiny", "seconds": 1,
                         "tracker-delay": ["0ms", "20ms", "40ms"], "predict": ["none", "landing"]})");
}

TEST(SweepLatency, PlanExpandsLatencyJobsWithStableIds) {
  const json file = json::array({fovea::core::parse_json(R"({"scenes": "default", "displays": "tiny", "distribution": ["a", "b"]})"),
                                 latency_part()});
  const Plan p = expand_sweep(file, "s.json", command_options());
  ASSERT_EQ(p.jobs.size(), 2u + 3u * 2u);
  EXPECT_TRUE(p.shared.empty());
  std::set<std::string> ids;
  for (std::size_t i = 0; i < p.jobs.size(); ++i) {
    const Job& j = p.jobs[i];
    ids.insert(j.id);
    EXPECT_EQ(j.id, settings_id(j.settings));
    const bool latency = i >= 2;
    EXPECT_EQ(job_command(j.settings), latency ? "latency" : "render");
    // Render jobs carry no "command": their ids are those of a render-only sweep.
    EXPECT_EQ(j.settings.contains("command"), latency);
    EXPECT_EQ(j.argv[1], latency ? "latency" : "render");
    EXPECT_EQ(std::count(j.argv.begin(), j.argv.end(), "--command"), 0);
    EXPECT_EQ(j.argv[j.argv.size() - 2], "--out");
    EXPECT_EQ(j.argv.back(), j.out);
    EXPECT_NE(std::find(j.argv.begin(), j.argv.end(), "--quiet"), j.argv.end());
    // A latency job measures quality at its own latency only.
    const auto inject = std::find(j.argv.begin(), j.argv.end(), "--inject-latency");
    ASSERT_EQ(inject != j.argv.end(), latency);
    if (latency) {
      EXPECT_EQ(*(inject + 1), "0");
    }
  }
  EXPECT_EQ(ids.size(), p.jobs.size());
  // Odometer order over the sorted keys (predict before tracker-delay, the last fastest),
  // values in file order.
  EXPECT_EQ(p.jobs[2].settings["predict"], "none");
  EXPECT_EQ(p.jobs[2].settings["tracker-delay"], "0ms");
  EXPECT_EQ(p.jobs[3].settings["tracker-delay"], "20ms");
  EXPECT_EQ(p.jobs[5].settings["predict"], "landing");
  // Same settings in another key order and file: the same ids.
  json reordered = json::object();
  const json part = latency_part();
  for (auto it = part.rbegin(); it != part.rend(); ++it) reordered[it.key()] = *it;
  const Plan q = expand_sweep(reordered, "other.json", command_options());
  ASSERT_EQ(q.jobs.size(), 6u);
  for (std::size_t i = 0; i < q.jobs.size(); ++i) EXPECT_EQ(q.jobs[i].id, p.jobs[i + 2].id);
  // The id hashes the command: a render job with a latency job's settings differs.
  json as_render = p.jobs[2].settings;
  as_render.erase("command");
  EXPECT_NE(settings_id(as_render), p.jobs[2].id);
  // An explicit --inject-latency is kept as given.
  json with_inject = latency_part();
  with_inject["inject-latency"] = "0,50";
  const Plan w = expand_sweep(with_inject, "w.json", command_options());
  const auto& a = w.jobs[0].argv;
  EXPECT_EQ(std::count(a.begin(), a.end(), "--inject-latency"), 1);
  EXPECT_EQ(*(std::find(a.begin(), a.end(), "--inject-latency") + 1), "0,50");
}

TEST(SweepLatency, PlanRefusesKeysTheCommandDoesNotHave) {
  auto error = [](const json& j) {
    try {
      expand_sweep(j, "bad.json", command_options());
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  json render_only = latency_part();
  render_only["png-every"] = 0;  // a render option, not a latency one
  EXPECT_NE(error(render_only).find("bad.json: key \"png-every\": unknown key"), std::string::npos) << error(render_only);
  EXPECT_NE(error(render_only).find("`fovea latency` option"), std::string::npos);
  EXPECT_NE(error(fovea::core::parse_json(R"({"command": "replay"})")).find("key \"command\""), std::string::npos);
  EXPECT_NE(error(fovea::core::parse_json(R"({"command": ["latency", "render"]})")).find("one command name"), std::string::npos);
  // Through the program: the real `fovea latency --help` options.
  const std::string dir = test::temp_dir("sweep-latency-plan");
  core::write_file_atomic(dir + "/s.json", latency_part().dump());
  const auto ok = test::run_fovea("sweep plan " + dir + "/s.json --out " + dir + "/plan.jsonl");
  ASSERT_EQ(ok.status, 0) << ok.err;
  EXPECT_EQ(fovea::core::parse_json(ok.out)["jobs"], 6);
  core::write_file_atomic(dir + "/bad.json", render_only.dump());
  const auto bad = test::run_fovea("sweep plan " + dir + "/bad.json --out " + dir + "/plan.jsonl");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("\"png-every\""), std::string::npos) << bad.err;
  fs::remove_all(dir);
}

// A `fovea latency` summary as it prints it: only the keys the sweep reads, plus noise.
json latency_summary(double g2p, double share, double psnr, double flip) {
  return {{"frames", 90},
          {"gaze_to_photon_ms", {{"n", 90}, {"median", g2p}, {"p95", g2p + 5}}},
          {"foveal_error_deg", {{"median", share * 4}, {"above_2deg", share}, {"over", "vsyncs"}}},
          {"config", {{"device", {{"name", "synthetic"}, {"driver", "test"}}}, {"seconds", 1}}},
          {"sweep", {{{"inject_ms", 25.0}, {"fovea_quality", {{"psnr_db", 1.0}, {"ldr_flip", 0.9}}}},
                     {{"inject_ms", 0.0}, {"gaze_to_photon_median_ms", g2p}, {"fovea_quality", {{"psnr_db", psnr}, {"ldr_flip", flip}, {"frames", 8}}}}}},
          {"plots", {"latency.png"}}};
}

TEST(SweepLatency, SummaryMetricsAreReadByKeyName) {
  const auto m = latency_metrics(latency_summary(30, 0.25, 28, 0.2));
  EXPECT_DOUBLE_EQ(m.at("gaze_to_photon_ms.median"), 30);
  EXPECT_DOUBLE_EQ(m.at("foveal_error_deg.above_2deg"), 0.25);
  EXPECT_DOUBLE_EQ(m.at("fovea_quality.psnr_db"), 28);  // the 0 ms point, not the 25 ms one
  EXPECT_DOUBLE_EQ(m.at("fovea_quality.ldr_flip"), 0.2);
  EXPECT_EQ(m.count("config.seconds"), 0u);
  // Missing parts leave their metrics out; a top-level fovea_quality wins over the point's.
  json s = latency_summary(30, 0.25, 28, 0.2);
  s["fovea_quality"] = {{"psnr_db", 31.0}};
  EXPECT_DOUBLE_EQ(latency_metrics(s).at("fovea_quality.psnr_db"), 31);
  s.erase("sweep");
  s.erase("fovea_quality");
  EXPECT_EQ(latency_metrics(s).count("fovea_quality.psnr_db"), 0u);
  EXPECT_EQ(latency_metrics(fovea::core::parse_json(R"({"sweep": [1, {"inject_ms": "0"}]})")).size(), 0u);
}

json render_report(double ms, double psnr) {
  const json eye = {{"fovea_psnr", psnr}, {"bands", {{{"e_min", 0.0}, {"e_max", 2.0}, {"psnr", psnr}}}}};
  return {{"gpu_ms", {{"total", ms}}}, {"summary", {{"left", eye}, {"right", eye}}}};
}

TEST(SweepLatency, ReportDrawsLatencyAgainstQualityAndSectionsPerScene) {
  const std::string dir = test::temp_dir("sweep-latency-report");
  const json file = json::array(
      {fovea::core::parse_json(R"({"scenes": ["cornell", "default"], "distribution": ["a", "b"], "budget": [0.2, 0.4],
                      "report": {"quality": ["fovea_psnr"], "section": "scene"}})"),
       latency_part()});
  const Plan plan = expand_sweep(file, "synthetic.json", command_options());
  ASSERT_EQ(plan.jobs.size(), 8u + 6u);
  std::map<std::string, json> settings_of;
  for (const Job& j : plan.jobs) {
    fs::create_directories(dir + "/" + j.out);
    settings_of[j.id] = j.settings;
    const json& s = j.settings;
    if (job_command(s) == "latency") {
      // Foveal error and gaze-to-photon grow with the tracker delay; landing halves the error.
      const double delay = std::stod(s["tracker-delay"].get<std::string>());
      const double share = (s["predict"] == "landing" ? 0.5 : 1.0) * (0.1 + delay / 100);
      core::write_file_atomic(dir + "/" + j.out + "/summary.json", latency_summary(20 + delay, share, 30 - delay / 10, 0.1 + share / 4).dump());
    } else {
      // In cornell, a is cheaper at the same quality: b's jobs are off its own front only
      // within cornell; default has its own fronts.
      const bool a = s["distribution"] == "a", cornell = s["scene"] == "cornell";
      const double budget = s["budget"].get<double>();
      core::write_file_atomic(dir + "/" + j.out + "/report.json",
                              render_report(100 * budget + (a ? 0 : 5), (cornell ? 30 : 20) + 10 * budget).dump());
    }
  }
  const std::string plan_path = dir + "/plan.jsonl";
  core::write_file_atomic(plan_path, plan_to_jsonl(plan));
  const auto r = test::run_fovea("sweep report " + plan_path + " --out " + dir + "/report --markdown " + dir + "/page.md");
  ASSERT_EQ(r.status, 0) << r.err;

  // The latency plots: x gaze-to-photon, y the foveal-error share and the fovea quality,
  // one series per predict mode (two colours drawn); matplotlib's PNG and SVG of each.
  for (const char* png : {"latency_vs_foveal_error_deg_above_2deg.png", "latency_vs_fovea_quality_ldr_flip.png",
                          "latency_vs_fovea_quality_psnr_db.png", "quality_vs_time_fovea_psnr_cornell.png",
                          "quality_vs_time_fovea_psnr_default.png", "bands_bands_psnr_default.png"}) {
    ASSERT_TRUE(fs::exists(dir + "/report/" + png)) << png;
    const core::Image img = core::read_png(dir + "/report/" + png);
    EXPECT_GT(img.width, 400) << png;
    const std::string svg = fs::path(dir + "/report/" + png).replace_extension(".svg").string();
    EXPECT_NE(test::read_text(svg).find("<svg"), std::string::npos) << svg;
    std::set<std::array<int, 3>> colours;
    for (const auto& p : img.pixels)
      if (std::abs(p.x - p.z) > 0.2f) colours.insert({int(p.x * 8), int(p.y * 8), int(p.z * 8)});
    EXPECT_GE(colours.size(), 2u) << png;
  }
  EXPECT_FALSE(fs::exists(dir + "/report/quality_vs_time_fovea_psnr.png"));  // per scene only

  // CSV columns of the latency metrics and the latency settings; a latency row's values.
  std::ifstream csv(dir + "/report/results.csv");
  std::string header, line;
  std::getline(csv, header);
  auto split = [](const std::string& l) {
    std::vector<std::string> v;
    std::string c;
    for (char ch : l + ",")
      if (ch == ',') v.push_back(c), c.clear();
      else c += ch;
    return v;
  };
  const std::vector<std::string> cols = split(header);
  auto col = [&](const std::string& name) {
    const auto it = std::find(cols.begin(), cols.end(), name);
    EXPECT_NE(it, cols.end()) << name << " in " << header;
    return std::size_t(it - cols.begin());
  };
  const std::size_t id = col("id"), g2p = col("gaze_to_photon_ms.median"), share = col("foveal_error_deg.above_2deg"),
                    psnr = col("fovea_quality.psnr_db"), delay = col("--tracker-delay"), command = col("--command");
  int latency_rows = 0;
  while (std::getline(csv, line)) {
    const auto v = split(line);
    ASSERT_EQ(v.size(), cols.size()) << line;
    const json& s = settings_of[v[id]];
    if (job_command(s) != "latency") continue;
    ++latency_rows;
    const double d = std::stod(s["tracker-delay"].get<std::string>());
    EXPECT_EQ(v[command], "latency");
    EXPECT_EQ(v[delay], s["tracker-delay"]);
    EXPECT_DOUBLE_EQ(std::stod(v[g2p]), 20 + d);
    EXPECT_DOUBLE_EQ(std::stod(v[share]), (s["predict"] == "landing" ? 0.5 : 1.0) * (0.1 + d / 100));
    EXPECT_DOUBLE_EQ(std::stod(v[psnr]), 30 - d / 10);
  }
  EXPECT_EQ(latency_rows, 6);

  // Fronts per scene and group; the page has a section per scene and the latency section.
  std::ifstream in(dir + "/report/results.json");
  const json j = fovea::core::parse_json(in);
  for (const char* key : {"cornell/a", "cornell/b", "default/a", "default/b"})
    EXPECT_EQ(j["pareto"]["fovea_psnr"][key].size(), 2u) << key;
  std::ifstream page_in(dir + "/page.md");
  const std::string page((std::istreambuf_iterator<char>(page_in)), std::istreambuf_iterator<char>());
  for (const char* text : {"## scene cornell", "## scene default", "### Equal samples", "### Equal time",
                           "## Latency against quality", "report/latency_vs_foveal_error_deg_above_2deg.png",
                           "fovea latency --display tiny", "--inject-latency 0", "### Which to pick",
                           // Equal quality at equal budget, a cheaper: a is never better, and
                           // a at 0.4 is the fastest within 5% of the best.
                           "- a against b in fovea_psnr at equal budget: better at 0 of 2.",
                           "- The fastest within 5% of it: a at budget 0.4 (34.00, 40.0 ms)."})
    EXPECT_NE(page.find(text), std::string::npos) << text;
  // Latency rows do not enter the render tables.
  const std::size_t latency_at = page.find("## Latency against quality");
  EXPECT_EQ(page.substr(0, latency_at).find("| all |"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fovea::sweep
