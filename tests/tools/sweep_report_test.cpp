// fovea sweep report: a synthetic result set with a known Pareto front per distribution,
// metric flattening and per-band averaging, CSV/JSON and the plots.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "cli.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"
#include "sweep/plan.hpp"
#include "sweep/report.hpp"

namespace fovea::sweep {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json render_report(double ms, double fovea_psnr, double flip, double band0) {
  auto eye = [&](double d) {
    return json{{"psnr", fovea_psnr - 10 + d},
                {"fovea_psnr", fovea_psnr + d},
                {"fovea_flip", flip + d * 0.01},
                {"band_psnr", {{{"e_min", 0.0}, {"e_max", 2.0}, {"pixels", 4}, {"psnr", band0 + d}},
                               {{"e_min", 2.0}, {"e_max", 4.0}, {"pixels", 9}, {"psnr", band0 - 5 + d}}}}};
  };
  return {{"frames", 8}, {"config", {{"budget", 0.5}}}, {"gpu_ms", {{"total", ms}, {"trace", ms / 2}}},
          {"latency", {{"gaze_to_photon_ms", 20 + ms}}},
          {"summary", {{"left", eye(-1)}, {"right", eye(1)}}}};
}

TEST(SweepReport, FlattensMetricsAndAveragesEyesAndBands) {
  const json r = render_report(10, 30, 0.2, 40);
  const auto m = flatten_metrics(r);
  EXPECT_DOUBLE_EQ(m.at("gpu_ms.total"), 10);
  EXPECT_DOUBLE_EQ(m.at("summary.left.fovea_psnr"), 29);
  EXPECT_DOUBLE_EQ(m.at("fovea_psnr"), 30);  // mean of the eyes
  EXPECT_DOUBLE_EQ(m.at("fovea_flip"), 0.2);
  EXPECT_EQ(m.count("budget"), 0u);  // config is settings, not a metric
  EXPECT_EQ(m.count("config.budget"), 0u);
  const auto b = band_metrics(r);
  ASSERT_EQ(b.count("band_psnr.psnr"), 1u);
  ASSERT_EQ(b.at("band_psnr.psnr").size(), 2u);
  EXPECT_DOUBLE_EQ(b.at("band_psnr.psnr")[0].value, 40);
  EXPECT_DOUBLE_EQ(b.at("band_psnr.psnr")[1].value, 35);
  EXPECT_DOUBLE_EQ(b.at("band_psnr.psnr")[1].e_min, 2);
}

TEST(SweepReport, ParetoFrontOfKnownPoints) {
  // (time, quality): (2, 29) is beaten by (1, 30); (4, 35) ties (3, 35) at more time.
  const std::vector<glm::dvec2> p = {{1, 30}, {2, 29}, {3, 35}, {4, 35}, {5, 40}, {5, 39}, {NAN, 50}};
  EXPECT_EQ(pareto_front(p, true), (std::vector<bool>{true, false, true, false, true, false, false}));
  // Lower is better (FLIP): the front runs the other way.
  const std::vector<glm::dvec2> f = {{1, 0.5}, {2, 0.3}, {3, 0.4}, {4, 0.1}};
  EXPECT_EQ(pareto_front(f, false), (std::vector<bool>{true, true, false, true}));
  EXPECT_TRUE(lower_is_better_by_name("fovea_flip"));
  EXPECT_TRUE(lower_is_better_by_name("gpu_ms.total"));
  EXPECT_TRUE(lower_is_better_by_name("latency.gaze_to_photon_ms"));
  EXPECT_FALSE(lower_is_better_by_name("fovea_psnr"));
}

// Whether the report's figures.json has the chart `stem` (what tools/plots/charts.py draws;
// whether it is drawn is SyntheticSweepGivesKnownFrontsTablesAndPlots' check).
bool has_chart(const std::string& report, const std::string& stem) {
  const json figures = core::parse_json(test::read_text(report + "/figures.json"));
  for (const auto& c : figures["charts"])
    if (c["file"] == stem) return true;
  return false;
}

TEST(SweepReport, SyntheticSweepGivesKnownFrontsTablesAndPlots) {
  const test::FiguresAsData figures;
  const std::string dir = test::temp_dir("sweep-report");
  const std::vector<RenderOption> opts = {{"distribution", true}, {"budget", true}, {"out", true}, {"quiet", false}};
  const Plan plan = expand_sweep(fovea::core::parse_json(R"({"distribution": ["a", "b"], "budget": [0.1, 0.2, 0.3, 0.4, 0.5]})"),
                                 "synthetic.json", opts);
  ASSERT_EQ(plan.jobs.size(), 10u);
  // distribution a, budgets 0.1..0.5: (time, fovea_psnr) as in ParetoFrontOfKnownPoints.
  // distribution b: (2, 31) beaten by (2, 33); (6, 32) beaten; 0.5 failed.
  const std::map<std::pair<std::string, double>, std::array<double, 2>> data = {
      {{"a", 0.1}, {1, 30}}, {{"a", 0.2}, {2, 29}}, {{"a", 0.3}, {3, 35}}, {{"a", 0.4}, {4, 35}}, {{"a", 0.5}, {5, 40}},
      {{"b", 0.1}, {2, 31}}, {{"b", 0.2}, {2, 33}}, {{"b", 0.3}, {6, 32}}};
  std::map<std::pair<std::string, double>, std::string> id;
  for (const Job& j : plan.jobs) {
    const auto key = std::make_pair(j.settings["distribution"].get<std::string>(), j.settings["budget"].get<double>());
    id[key] = j.id;
    if (const auto it = data.find(key); it != data.end()) {
      fs::create_directories(dir + "/" + j.out);
      core::write_file_atomic(dir + "/" + j.out + "/report.json",
                              render_report(it->second[0], it->second[1], 1.0 / it->second[1], 50).dump());
    } else if (key.first == "b" && key.second == 0.5) {
      fs::create_directories(dir + "/failed");
      core::write_file_atomic(dir + "/failed/" + j.id + ".json", json{{"id", j.id}, {"exit_code", 2}}.dump());
    }  // b 0.4: never ran
  }
  const std::string plan_path = dir + "/plan.jsonl";
  core::write_file_atomic(plan_path, plan_to_jsonl(plan));
  const auto r = test::run_fovea("sweep report " + plan_path + " --out " + dir + "/report");
  ASSERT_EQ(r.status, 0) << r.err;

  std::ifstream in(dir + "/report/results.json");
  const json j = fovea::core::parse_json(in);
  EXPECT_EQ(j["counts"]["done"], 8);
  EXPECT_EQ(j["counts"]["failed"], 1);
  EXPECT_EQ(j["counts"]["missing"], 1);
  const std::string never_ran = id[{"b", 0.4}];
  EXPECT_EQ(j["missing"][0], never_ran);
  const json front_a = {id[{"a", 0.1}], id[{"a", 0.3}], id[{"a", 0.5}]}, front_b = {id[{"b", 0.2}]};
  EXPECT_EQ(j["pareto"]["fovea_psnr"]["a"], front_a);
  EXPECT_EQ(j["pareto"]["fovea_psnr"]["b"], front_b);
  // fovea_flip = 1 / fovea_psnr here, lower is better: the same jobs win.
  EXPECT_EQ(j["pareto"]["fovea_flip"]["a"], j["pareto"]["fovea_psnr"]["a"]);
  for (const auto& row : j["jobs"])
    if (row["id"] == front_a[1]) {
      EXPECT_EQ(row["status"], "done");
      EXPECT_DOUBLE_EQ(row["metrics"]["fovea_psnr"].get<double>(), 35);
      EXPECT_EQ(row["pareto"]["fovea_psnr"], true);
      EXPECT_DOUBLE_EQ(row["bands"]["band_psnr.psnr"][1]["value"].get<double>(), 45);
    }

  std::ifstream csv(dir + "/report/results.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("id,status,--budget,--distribution,", 0), 0u) << header;
  EXPECT_NE(header.find("band_psnr.psnr[0-2]"), std::string::npos);
  EXPECT_NE(header.find("pareto:fovea_psnr"), std::string::npos);
  int rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 10);

  // The figures: drawn by matplotlib from figures.json, PNG and SVG.
  for (const char* stem : {"quality_vs_time_fovea_psnr", "quality_vs_budget_fovea_psnr", "quality_vs_time_fovea_flip",
                           "bands_band_psnr_psnr", "latency_vs_fovea_psnr"}) {
    EXPECT_TRUE(has_chart(dir + "/report", stem)) << stem;
    if (test::kFiguresDrawn) {
      const core::Image img = core::read_png(dir + "/report/" + stem + ".png");
      EXPECT_GT(img.width, 400) << stem;
      EXPECT_NE(test::read_text(dir + "/report/" + stem + ".svg").find("<svg"), std::string::npos) << stem;
    }
  }
  const json fig = core::parse_json(test::read_text(dir + "/report/figures.json"));
  EXPECT_EQ(fig["figure"], "charts");
  bool pareto = false;
  for (const auto& c : fig["charts"])
    if (c["file"] == "quality_vs_time_fovea_psnr") {
      pareto = true;
      // Human axis labels, not keys; each point labelled with its budget; the front ringed.
      EXPECT_EQ(c["y_label"], "fovea PSNR (dB)");
      for (const auto& s : c["series"])
        if (s["label"] == "a") {
          EXPECT_EQ(s["point_labels"], json({"0.1", "0.2", "0.3", "0.4", "0.5"}));
          EXPECT_EQ(s["emphasised"], json({true, false, true, false, true}));
        }
    }
  EXPECT_TRUE(pareto);
  fs::remove_all(dir);
}

// The page and the figures' data: drawn without Python (matplotlib was nearly all of this
// test's time; what it draws from such data is checked above).
TEST(SweepReport, SectionsByTwoSettingsAndSpeedUpAtEqualQuality) {
  const test::PythonOverride no_python("/nonexistent/python3");
  const std::string dir = test::temp_dir("sweep-report-speedup");
  const std::vector<RenderOption> opts = {{"scene", true}, {"display", true}, {"distribution", true},
                                          {"budget", true}, {"out", true},     {"quiet", false},
                                          {"raster-filter", true}};
  const json file = core::parse_json(R"([
    {"scenes": "default", "displays": ["p1", "p2"], "distribution": "vp", "budget": [0.1, 0.2, 0.4],
     "report": {"quality": ["fovea_flip", "fovea_psnr"], "section": ["scene", "display"],
                "speedup": {"of": "vp", "over": "full", "tolerance": 0.05}}},
    {"scenes": "default", "displays": ["p1", "p2"], "distribution": "full", "raster-filter": "gaussian"}])");
  const Plan plan = expand_sweep(file, "synthetic.json", opts);
  ASSERT_EQ(plan.jobs.size(), 8u);
  // full: 100 ms, FLIP 0.200, 1000 samples. vp on p1: FLIP 0.30, 0.209 (within 5%), 0.19 at
  // 10, 20, 40 ms with budget * 1000 samples: the pick is budget 0.2, 5.00x for a samples
  // ratio of 5. On p2 vp never gets within 5% (best 0.25). Tracing costs 50 ms per 1000 samples
  // for full, 60 for vp.
  for (const Job& j : plan.jobs) {
    const json& st = j.settings;
    const bool full = st["distribution"] == "full", p1 = st["display"] == "p1";
    const double budget = full ? 1.0 : st["budget"].get<double>();
    const double flip = full ? 0.2 : !p1 ? 0.25 + budget : budget < 0.15 ? 0.3 : budget < 0.3 ? 0.209 : 0.19;
    json rep = render_report(100 * budget, full ? 30 : 31, flip, 40);
    rep["samples_traced_per_eye"] = 1000 * budget;
    rep["cpu_ms"] = {{"total", 110 * budget}};
    if (!full) rep["gpu_ms"]["trace"] = 60 * budget;  // a vp sample costs 1.2x a full one to trace
    fs::create_directories(dir + "/" + j.out);
    core::write_file_atomic(dir + "/" + j.out + "/report.json", rep.dump());
  }
  const std::string plan_path = dir + "/plan.jsonl";
  core::write_file_atomic(plan_path, plan_to_jsonl(plan));
  const auto r = test::run_fovea("sweep report " + plan_path + " --out " + dir + "/report --markdown " + dir + "/page.md");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string page = test::read_text(dir + "/page.md");
  for (const char* text :
       {"One section per display: [p1](#display-p1), [p2](#display-p2)", "## display p1\n", "## display p2\n",
        "## vp against full at equal fovea_flip",
        "| display p1 | 1000 | 100 / 110 | 0.2000 | 0.2 | 200 | 20.0 / 22.0 | 0.2090 | **5.00×** | 5.00× | 5.00 | 1.00 | 50.0 / 60.0 (1.20) | fovea_psnr 30.00 → 31.00 |",
        "| display p2 | 1000 | 100 / 110 | 0.2000 | none as good (best: 0.3500 at budget 0.1) | – | – | – | – | – | – | – | – | – |"})
    EXPECT_NE(page.find(text), std::string::npos) << text << "\n" << page;
  // An option only one group ran with is named, in the speed-up's text and in each section; the
  // options every job shares are the command's.
  EXPECT_NE(page.find(" The full jobs run with `--raster-filter gaussian`. *Speed-up*"), std::string::npos) << page;
  const std::size_t p2 = page.find("## display p2\n");
  EXPECT_NE(page.find("\nThe full jobs also run with `--raster-filter gaussian`.\n", p2), std::string::npos) << page;
  EXPECT_EQ(page.find("The vp jobs"), std::string::npos) << page;
  // The scene does not vary: it names no section; the fronts and plots are per display.
  const json j = core::parse_json(test::read_text(dir + "/report/results.json"));
  EXPECT_TRUE(j["pareto"]["fovea_flip"].contains("p1/vp")) << j["pareto"].dump();
  EXPECT_TRUE(has_chart(dir + "/report", "quality_vs_time_fovea_flip_p2"));

  // Both keys vary: sections by scene and display, titled with both.
  const json two = core::parse_json(R"({"scenes": ["a", "b"], "displays": ["p1", "p2"], "distribution": "vp",
                                        "report": {"quality": ["fovea_flip"], "section": ["scene", "display"]}})");
  const Plan plan2 = expand_sweep(two, "synthetic.json", opts);
  const std::string dir2 = dir + "/two";
  for (const Job& jb : plan2.jobs) {
    fs::create_directories(dir2 + "/" + jb.out);
    core::write_file_atomic(dir2 + "/" + jb.out + "/report.json", render_report(10, 30, 0.2, 40).dump());
  }
  core::write_file_atomic(dir2 + "/plan.jsonl", plan_to_jsonl(plan2));
  const auto r2 = test::run_fovea("sweep report " + dir2 + "/plan.jsonl --out " + dir2 + "/report --markdown " + dir2 + "/page.md");
  ASSERT_EQ(r2.status, 0) << r2.err;
  const std::string page2 = test::read_text(dir2 + "/page.md");
  EXPECT_NE(page2.find("One section per scene and display: [a p1](#scene-a-display-p1),"), std::string::npos) << page2;
  EXPECT_NE(page2.find("## scene b, display p2\n"), std::string::npos) << page2;
  EXPECT_EQ(page2.find("## vp against"), std::string::npos);  // no speedup configured, no such table
  EXPECT_TRUE(has_chart(dir2 + "/report", "quality_vs_time_fovea_flip_b_p2"));

  // At listed budgets instead of equal quality (a sweep that measures time only): one row per
  // budget a section has, whatever its quality; times below 10 ms keep three digits.
  json at = file;
  at[0]["report"]["speedup"] = {{"of", "vp"}, {"over", "full"}, {"at", {0.1, 0.4, 0.3}}};
  core::write_file_atomic(plan_path, plan_to_jsonl(expand_sweep(at, "synthetic.json", opts)));
  const auto r4 = test::run_fovea("sweep report " + plan_path + " --out " + dir + "/report --markdown " + dir + "/at.md");
  ASSERT_EQ(r4.status, 0) << r4.err;
  const std::string page4 = test::read_text(dir + "/at.md");
  for (const char* text :
       {"## vp against full at budget 0.1, 0.4, 0.3\n",
        "| display p1 | 1000 | 100 / 110 | 0.2000 | 0.1 | 100 | 10.0 / 11.0 | 0.3000 | **10.00×** | 10.00× | 10.00 | 1.00 | 50.0 / 60.0 (1.20) |",
        "| display p1 | 1000 | 100 / 110 | 0.2000 | 0.4 | 400 | 40.0 / 44.0 | 0.1900 | **2.50×** | 2.50× | 2.50 | 1.00 |",
        "| display p2 | 1000 | 100 / 110 | 0.2000 | 0.1 | 100 | 10.0 / 11.0 | 0.3500 | **10.00×** |"})
    EXPECT_NE(page4.find(text), std::string::npos) << text << "\n" << page4;
  EXPECT_EQ(page4.find("| 0.3 |"), std::string::npos) << "a budget no job ran got a row";
  EXPECT_EQ(page4.find("at equal fovea_flip"), std::string::npos);

  // A malformed speedup names the key.
  json bad = file;
  bad[0]["report"]["speedup"] = {{"of", "vp"}};
  core::write_file_atomic(plan_path, plan_to_jsonl(expand_sweep(bad, "synthetic.json", opts)));
  const auto r3 = test::run_fovea("sweep report " + plan_path + " --out " + dir + "/report");
  EXPECT_EQ(r3.status, 2);
  EXPECT_NE(r3.err.find("report.speedup"), std::string::npos) << r3.err;
  bad[0]["report"]["speedup"] = {{"of", "vp"}, {"over", "full"}, {"at", {"default"}}};
  core::write_file_atomic(plan_path, plan_to_jsonl(expand_sweep(bad, "synthetic.json", opts)));
  const auto r5 = test::run_fovea("sweep report " + plan_path + " --out " + dir + "/report");
  EXPECT_EQ(r5.status, 2);
  EXPECT_NE(r5.err.find("report.speedup: at"), std::string::npos) << r5.err;
  fs::remove_all(dir);
}

// A list of speed-ups is a table each; a list of qualities asks for each to be as good: at
// equal fovea_flip alone the pick on p1 is budget 0.2, but its fovea_psnr is 10% worse than the
// full job's, so at equal fovea_flip and fovea_psnr it is budget 0.4. On p2 no budget's is.
TEST(SweepReport, SpeedUpAtEqualQualityInEveryListedMetric) {
  const test::PythonOverride no_python("/nonexistent/python3");
  const std::string dir = test::temp_dir("sweep-report-speedups");
  const std::vector<RenderOption> opts = {{"display", true}, {"distribution", true}, {"budget", true},
                                          {"out", true},     {"quiet", false}};
  const json file = core::parse_json(R"([
    {"displays": ["p1", "p2"], "distribution": "vp", "budget": [0.1, 0.2, 0.4],
     "report": {"quality": ["fovea_flip", "fovea_psnr"], "section": "display",
                "speedup": [{"of": "vp", "over": "full", "tolerance": 0.05},
                            {"of": "vp", "over": "full", "quality": ["fovea_flip", "fovea_psnr"], "tolerance": 0.05}]}},
    {"displays": ["p1", "p2"], "distribution": "full"}])");
  const Plan plan = expand_sweep(file, "synthetic.json", opts);
  for (const Job& j : plan.jobs) {
    const bool full = j.settings["distribution"] == "full";
    const double budget = full ? 1.0 : j.settings["budget"].get<double>();
    const double flip = full ? 0.2 : budget < 0.15 ? 0.3 : budget < 0.3 ? 0.209 : 0.19;
    const double psnr = full ? 30 : budget < 0.3 || j.settings["display"] == "p2" ? 27 : 31;  // p2: never as good
    json rep = render_report(100 * budget, psnr, flip, 40);
    rep["samples_traced_per_eye"] = 1000 * budget;
    fs::create_directories(dir + "/" + j.out);
    core::write_file_atomic(dir + "/" + j.out + "/report.json", rep.dump());
  }
  const std::string plan_path = dir + "/plan.jsonl";
  core::write_file_atomic(plan_path, plan_to_jsonl(plan));
  const auto r =
      test::run_fovea("sweep report " + plan_path + " --out " + dir + "/report --markdown " + dir + "/page.md");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string page = test::read_text(dir + "/page.md");
  const std::size_t one = page.find("## vp against full at equal fovea_flip\n"),
                    both = page.find("## vp against full at equal fovea_flip and fovea_psnr\n");
  ASSERT_NE(one, std::string::npos) << page;
  ASSERT_NE(both, std::string::npos) << page;
  ASSERT_LT(one, both) << "the tables keep the sweep file's order";
  const std::string first = page.substr(one, both - one), second = page.substr(both);
  EXPECT_NE(first.find("| 0.2 | 200 | 20.0 / – | 0.2090 | **5.00×** |"), std::string::npos) << first;
  EXPECT_NE(second.find("whose fovea_flip and fovea_psnr are each at least as good as its, within 5% "
                        "(\"as good\": at most 1 + 0.05 times the full job's where lower is better, at least "
                        "1 − 0.05 times where higher is). The columns are those of the first table."),
            std::string::npos)
      << second;
  EXPECT_NE(second.find("| 0.4 | 400 | 40.0 / – | 0.1900 | **2.50×** |"), std::string::npos) << second;
  EXPECT_NE(second.find("fovea_psnr 30.00 → 31.00 |"), std::string::npos) << second;
  EXPECT_NE(page.find("| display p2 | 1000 | 100 / – | 0.2000 | none as good in each (best fovea_flip: 0.1900 at "
                      "budget 0.4) |"),
            std::string::npos)
      << page;

  // An empty list of qualities names the key.
  json bad = file;
  bad[0]["report"]["speedup"][1]["quality"] = json::array();
  core::write_file_atomic(plan_path, plan_to_jsonl(expand_sweep(bad, "synthetic.json", opts)));
  const auto r2 = test::run_fovea("sweep report " + plan_path + " --out " + dir + "/report");
  EXPECT_EQ(r2.status, 2);
  EXPECT_NE(r2.err.find("report.speedup: quality"), std::string::npos) << r2.err;
  fs::remove_all(dir);
}

// report.repeat: runs that differ only in the seed are one row on the page and in the plots,
// their mean ± standard deviation; the CSV keeps every run.
TEST(SweepReport, RepeatedRunsAreOneRowWithTheirSpread) {
  const test::PythonOverride no_python("/nonexistent/python3");  // the page and the data, as above
  const std::string dir = test::temp_dir("sweep-report-repeat");
  const std::vector<RenderOption> opts = {{"distribution", true}, {"budget", true}, {"seed", true}, {"out", true},
                                          {"quiet", false}};
  const Plan plan = expand_sweep(core::parse_json(R"([
    {"distribution": "a", "budget": [0.1, 0.2], "seed": [0, 1, 2],
     "report": {"quality": ["fovea_flip"], "repeat": "seed"}},
    {"distribution": "b", "budget": 0.1}])"), "synthetic.json", opts);
  ASSERT_EQ(plan.jobs.size(), 7u);
  for (const Job& j : plan.jobs) {
    const bool a = j.settings["distribution"] == "a";
    const double seed = a ? j.settings["seed"].get<double>() : 0, budget = j.settings["budget"].get<double>();
    // a at 0.1: times 10, 12, 14 and FLIP 0.20, 0.21, 0.22 over the seeds; at 0.2 all 20 / 0.15.
    json rep = budget < 0.15 && a ? render_report(10 + 2 * seed, 30, 0.2 + 0.01 * seed, 40)
                                  : render_report(a ? 20 : 30, 30, a ? 0.15 : 0.3, 40);
    fs::create_directories(dir + "/" + j.out);
    core::write_file_atomic(dir + "/" + j.out + "/report.json", rep.dump());
  }
  core::write_file_atomic(dir + "/plan.jsonl", plan_to_jsonl(plan));
  const auto r = test::run_fovea("sweep report " + dir + "/plan.jsonl --out " + dir + "/report --markdown " + dir + "/page.md");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string page = test::read_text(dir + "/page.md");
  for (const char* text : {"Jobs: 7 done of 7.", "differ only in `seed` are one row",
                           "| a | 0.1 | – | 12.0 ± 2.0 | 0.2100 ± 0.0100 | yes |", "| a | 0.2 | – | 20.0 | 0.1500 | yes |",
                           "| b | 0.1 | – | 30.0 | 0.3000 | yes |"})
    EXPECT_NE(page.find(text), std::string::npos) << text << "\n" << page;
  // One point per (distribution, budget) in the plot; every run in the CSV, each with its
  // row's front membership.
  const json fig = core::parse_json(test::read_text(dir + "/report/figures.json"));
  for (const auto& c : fig["charts"]) {
    if (c["file"] != "quality_vs_time_fovea_flip") continue;
    for (const auto& series : c["series"]) {
      if (series["label"] == "a") {
        EXPECT_EQ(series["points"].size(), 2u);
      }
    }
  }
  const json res = core::parse_json(test::read_text(dir + "/report/results.json"));
  ASSERT_EQ(res["jobs"].size(), 7u);
  for (const auto& job : res["jobs"]) EXPECT_EQ(job["pareto"]["fovea_flip"], true) << job.dump();

  // A block another tool wrote into the page survives the page's regeneration, once; text
  // outside such a block does not.
  const std::string block = "<!-- kept: bench -->\n## measured elsewhere\n\n| a | b |\n<!-- /kept: bench -->";
  core::write_file_atomic(dir + "/page.md", page + "\nstale text\n" + block + "\n");
  for (int run = 0; run < 2; ++run) {
    const auto again =
        test::run_fovea("sweep report " + dir + "/plan.jsonl --out " + dir + "/report --markdown " + dir + "/page.md");
    ASSERT_EQ(again.status, 0) << again.err;
  }
  const std::string regenerated = test::read_text(dir + "/page.md");
  EXPECT_EQ(regenerated, page + "\n" + block + "\n");
  fs::remove_all(dir);
}

TEST(SweepReport, WithoutPythonWritesTheDataAndSaysHowToDrawTheFigures) {
  const std::string dir = test::temp_dir("sweep-report-nopython");
  const std::vector<RenderOption> opts = {{"distribution", true}, {"budget", true}, {"out", true}, {"quiet", false}};
  const Plan plan = expand_sweep(fovea::core::parse_json(R"({"distribution": ["a"], "budget": [0.1, 0.2]})"),
                                 "synthetic.json", opts);
  for (const Job& j : plan.jobs) {
    const double budget = j.settings["budget"].get<double>();
    fs::create_directories(dir + "/" + j.out);
    core::write_file_atomic(dir + "/" + j.out + "/report.json",
                            render_report(100 * budget, 30 + 10 * budget, 0.3 - budget, 40).dump());
  }
  const std::string plan_path = dir + "/plan.jsonl";
  core::write_file_atomic(plan_path, plan_to_jsonl(plan));
  const std::string report = dir + "/report";
  const auto r = [&] {
    const test::PythonOverride no_python("/nonexistent/python3");
    return test::run_fovea("sweep report " + plan_path + " --out " + report);
  }();
  ASSERT_EQ(r.status, 0) << r.err;
  // The data is all there; no figure was drawn, and the summary lists only what was written.
  EXPECT_TRUE(fs::exists(report + "/results.json"));
  const json fig = core::parse_json(test::read_text(report + "/figures.json"));
  EXPECT_EQ(fig["figure"], "charts");
  EXPECT_FALSE(fig["charts"].empty());
  for (const auto& e : fs::directory_iterator(report))
    EXPECT_TRUE(e.path().extension() != ".png" && e.path().extension() != ".svg") << e.path();
  EXPECT_EQ(core::parse_json(r.out)["files"], json({"results.csv", "results.json", "figures.json"}));
  // The warning names the script and the interpreter; the note gives the exact command.
  EXPECT_NE(r.err.find("warning: figures not drawn by tools/plots/charts.py"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/nonexistent/python3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("fovea plot " + report + "/figures.json"), std::string::npos) << r.err;
  // That command draws them once the interpreter is there.
  const auto p = test::run_fovea("plot " + report + "/figures.json");
  ASSERT_EQ(p.status, 0) << p.err;
  EXPECT_EQ(test::read_text(report + "/quality_vs_time_fovea_psnr.png").rfind("\x89PNG\r\n\x1a\n", 0), 0u);
  EXPECT_NE(test::read_text(report + "/quality_vs_time_fovea_psnr.svg").find("<svg"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fovea::sweep
