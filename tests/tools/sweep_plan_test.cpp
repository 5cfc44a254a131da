// fovea sweep plan: expansion counts, stable ids, shared references, errors; shard partition.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>

#include "cli.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"
#include "sweep/plan.hpp"

namespace fovea::sweep {
namespace {

using nlohmann::json;

std::vector<RenderOption> render_options() {
  return {{"scene", true},  {"display", true},     {"gaze", true},      {"frames", true}, {"distribution", true},
          {"budget", true}, {"reference", true},   {"png-every", true}, {"out", true},    {"no-blur", false},
          {"quiet", false}};
}

json sweep_file() {
  return fovea::core::parse_json(R"({"scenes": ["cornell", "default"], "displays": "tiny", "frames": 2,
    "distribution": ["visual-polar", "cartesian", "log-polar"], "budget": {"from": 0.1, "to": 0.3, "step": 0.1},
    "reference": 16, "no-blur": [true, false]})");
}

TEST(SweepPlan, FnvMatchesPublishedVectors) {
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ULL);
  // Computed independently (Python) over the compact dump {"a":"x","b":1}.
  EXPECT_EQ(settings_id(fovea::core::parse_json(R"({"b": 1, "a": "x"})")), "1fc46df94e7ae50d");
}

TEST(SweepPlan, ExpandsEveryCombinationWithStableIds) {
  const Plan p = expand_sweep(sweep_file(), "s.json", render_options());
  ASSERT_EQ(p.jobs.size(), 2u * 3u * 3u * 2u);
  std::set<std::string> ids;
  std::set<double> budgets;
  for (const Job& j : p.jobs) {
    ids.insert(j.id);
    EXPECT_EQ(j.id, settings_id(j.settings));
    EXPECT_EQ(j.id.size(), 16u);
    EXPECT_EQ(j.out, "jobs/" + j.id);
    budgets.insert(j.settings["budget"].get<double>());
    // The exact command: render, every setting, quiet, last-frame PNG only, --out last.
    ASSERT_GE(j.argv.size(), 4u);
    EXPECT_EQ(j.argv[0], "fovea");
    EXPECT_EQ(j.argv[1], "render");
    EXPECT_EQ(j.argv[j.argv.size() - 2], "--out");
    EXPECT_EQ(j.argv.back(), j.out);
    EXPECT_NE(std::find(j.argv.begin(), j.argv.end(), "--quiet"), j.argv.end());
    const bool blur_off = std::find(j.argv.begin(), j.argv.end(), "--no-blur") != j.argv.end();
    EXPECT_EQ(blur_off, j.settings.contains("no-blur"));  // a false flag is simply absent
  }
  EXPECT_EQ(ids.size(), p.jobs.size());
  EXPECT_EQ(budgets, (std::set<double>{0.1, 0.2, 0.3}));  // the end of the range included, no 0.30000000000000004

  // Key order in the file does not matter; the ids are the same on every expansion.
  json reordered = json::object();
  const json f = sweep_file();
  for (auto it = f.rbegin(); it != f.rend(); ++it) reordered[it.key()] = *it;
  const Plan q = expand_sweep(reordered, "other.json", render_options());
  ASSERT_EQ(q.jobs.size(), p.jobs.size());
  for (std::size_t i = 0; i < p.jobs.size(); ++i) EXPECT_EQ(q.jobs[i].id, p.jobs[i].id);
}

TEST(SweepPlan, ReferencesAreSharedPerSceneAndDisplay) {
  const Plan p = expand_sweep(sweep_file(), "s.json", render_options());
  ASSERT_EQ(p.shared.size(), 2u);  // cornell and default, one display, one spp
  std::map<std::string, int> users;
  for (const Job& j : p.jobs) {
    ASSERT_EQ(j.shared.size(), 1u);
    const SharedInput* s = p.find_shared(j.shared[0]);
    ASSERT_NE(s, nullptr);
    EXPECT_EQ(s->settings["scene"], j.settings["scene"]);
    EXPECT_EQ(s->settings["spp"], 16);
    // The job loads the shared reference instead of rendering one.
    const auto ref = std::find(j.argv.begin(), j.argv.end(), "--reference");
    ASSERT_NE(ref, j.argv.end());
    EXPECT_EQ(*(ref + 1), s->out);
    ++users[s->id];
  }
  for (const auto& s : p.shared) {
    EXPECT_EQ(users[s.id], 18);
    ASSERT_EQ(s.commands.size(), 2u);  // left and right eye
    EXPECT_EQ(s.commands[0][1], "reference");
    EXPECT_EQ(s.commands[0].back(), "--quiet");
    EXPECT_EQ(s.commands[1][s.commands[1].size() - 2], s.out + "/reference_right.exr");
  }
  // No reference, no shared input.
  json f = sweep_file();
  f.erase("reference");
  EXPECT_TRUE(expand_sweep(f, "s.json", render_options()).shared.empty());
}

// The shared reference traces the render's light transport: the frame's one bounce without
// Russian roulette by default, a swept --bounces per value (auto: the reference's defaults).
TEST(SweepPlan, SharedReferencesTraceTheRendersTransport) {
  const auto has = [](const std::vector<std::string>& a, const std::string& k, const std::string& v) {
    const auto it = std::find(a.begin(), a.end(), k);
    return it != a.end() && it + 1 != a.end() && *(it + 1) == v;
  };
  const Plan p = expand_sweep(sweep_file(), "s.json", render_options());
  for (const auto& s : p.shared) {
    EXPECT_TRUE(has(s.commands[0], "--bounces", "1")) << s.settings.dump();
    EXPECT_TRUE(has(s.commands[0], "--rr-start", "1000"));
  }
  std::vector<RenderOption> options = render_options();
  options.push_back({"bounces", true});
  json f = sweep_file();
  f["scenes"] = "cornell";
  f["bounces"] = json::array({2, "auto"});
  const Plan q = expand_sweep(f, "s.json", options);
  ASSERT_EQ(q.shared.size(), 2u);  // one per transport
  for (const auto& s : q.shared) {
    if (s.settings["bounces"] == "auto") {
      EXPECT_EQ(std::find(s.commands[0].begin(), s.commands[0].end(), "--bounces"), s.commands[0].end());
    } else {
      EXPECT_TRUE(has(s.commands[0], "--bounces", "2"));
    }
  }
}

// A list of sweeps is their union: cartesian without budgets next to budgeted distributions.
TEST(SweepPlan, AListOfSweepsIsTheirUnion) {
  const json list = fovea::core::parse_json(R"([
    {"scenes": "cornell", "distribution": ["visual-polar", "log-polar"], "budget": [0.2, 0.3], "reference": 8,
     "report": {"group": "distribution"}},
    {"scenes": "cornell", "distribution": "cartesian", "reference": 8},
    {"scenes": "cornell", "distribution": "log-polar", "budget": 0.3, "reference": 8}])");
  const Plan p = expand_sweep(list, "list.json", render_options());
  ASSERT_EQ(p.jobs.size(), 5u);  // 4 + 1, the third part's job is already planned
  EXPECT_EQ(p.jobs[4].settings, json({{"distribution", "cartesian"}, {"reference", 8}, {"scene", "cornell"}}));
  EXPECT_EQ(p.shared.size(), 1u);  // one reference for all of them
  EXPECT_EQ(p.header["report"]["group"], "distribution");
  EXPECT_EQ(p.header["jobs"], 5);
  try {
    expand_sweep(fovea::core::parse_json(R"([{"scenes": "cornell"}, {"budgett": 1}])"), "list.json", render_options());
    ADD_FAILURE() << "unknown key accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("list.json[1]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(expand_sweep(json::array(), "list.json", render_options()), core::InputError);
}

TEST(SweepPlan, RejectsBadSweepFilesNamingKeyAndFile) {
  auto error = [](const std::string& text) {
    try {
      expand_sweep(fovea::core::parse_json(text), "bad.json", render_options());
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error(R"({"kappa": 3})").find("bad.json: key \"kappa\": unknown key"), std::string::npos);
  EXPECT_NE(error(R"({"out": "x"})").find("\"out\""), std::string::npos);
  EXPECT_NE(error(R"({"budget": []})").find("empty list"), std::string::npos);
  EXPECT_NE(error(R"({"budget": {"from": 1, "to": 0, "step": 1}})").find("to < from"), std::string::npos);
  EXPECT_NE(error(R"({"budget": {"from": 0, "to": 1, "step": 0}})").find("step > 0"), std::string::npos);
  EXPECT_NE(error(R"({"budget": {"from": 0, "to": 1, "stride": 1}})").find("stride"), std::string::npos);
  EXPECT_NE(error(R"({"no-blur": "yes"})").find("true or false"), std::string::npos);
  EXPECT_NE(error(R"({"budget": true})").find("string or a number"), std::string::npos);
  EXPECT_NE(error(R"({"scenes": "a", "scene": "b"})").find("already set"), std::string::npos);
  EXPECT_NE(error(R"({"reference": 1.5})").find("whole numbers"), std::string::npos);
  EXPECT_NE(error(R"([1, 2])").find("JSON object"), std::string::npos);
  EXPECT_NE(error(R"({"report": {"qualty": "psnr"}})").find("key \"report.qualty\": unknown key"), std::string::npos);
  // Through the program: exit 2 and the key named.
  const std::string dir = test::temp_dir("sweep-plan");
  core::write_file_atomic(dir + "/bad.json", R"({"scenes": "cornell", "kappa": [1, 2]})");
  const auto r = test::run_fovea("sweep plan " + dir + "/bad.json --out " + dir + "/plan.jsonl");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("\"kappa\""), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}

TEST(SweepPlan, PlanFileRoundTripsAndTheProgramUsesRenderOptions) {
  const std::string dir = test::temp_dir("sweep-plan");
  core::write_file_atomic(dir + "/s.json",
                          R"({"scenes": "cornell", "displays": "tiny", "frames": [1, 2], "distribution": ["cartesian", "visual-polar"],
                              "reference": 8, "stereo-share": "gather"})");
  const auto r = test::run_fovea("sweep plan " + dir + "/s.json --out " + dir + "/plan.jsonl");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(fovea::core::parse_json(r.out)["jobs"], 4);
  const Plan p = read_plan(dir + "/plan.jsonl");
  EXPECT_EQ(p.jobs.size(), 4u);
  EXPECT_EQ(p.shared.size(), 1u);
  EXPECT_EQ(p.header["jobs"], 4);
  core::write_file_atomic(dir + "/again.jsonl", plan_to_jsonl(p));
  const auto again = read_plan(dir + "/again.jsonl");
  for (std::size_t i = 0; i < p.jobs.size(); ++i) {
    EXPECT_EQ(again.jobs[i].id, p.jobs[i].id);
    EXPECT_EQ(again.jobs[i].argv, p.jobs[i].argv);
  }
  // A broken plan line is named by file and line.
  core::write_file_atomic(dir + "/broken.jsonl", plan_to_jsonl(p) + "{\"type\": \"job\"}\n");
  try {
    read_plan(dir + "/broken.jsonl");
    ADD_FAILURE() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.jsonl:7"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(SweepPlan, HelpOptionsParsed) {
  const auto o = parse_help_options(
      "usage: x\n  --scene S             a scene\n  --display NAME|FILE   preset\n  --no-blur             skip\n"
      "                        --not-an-option here\n  --help                this text\n  --quiet\n"
      "  --eq=1  not one\n  ---x  not one\n  --Upper  not one\n  --trailing \n   --indented  not one\n  --2d X\n");
  ASSERT_EQ(o.size(), 5u);
  EXPECT_EQ(o[0].name, "scene");
  EXPECT_TRUE(o[0].valued);
  EXPECT_TRUE(o[1].valued);
  EXPECT_EQ(o[2].name, "no-blur");
  EXPECT_FALSE(o[2].valued);
  EXPECT_EQ(o[3].name, "quiet");  // a flag at the line's end
  EXPECT_FALSE(o[3].valued);
  EXPECT_EQ(o[4].name, "2d");
  EXPECT_TRUE(o[4].valued);
}

TEST(SweepShard, EveryJobInExactlyOneShard) {
  for (std::size_t jobs : {0u, 1u, 5u, 23u, 64u})
    for (int n = 1; n <= 7; ++n) {
      std::vector<int> seen(jobs, 0);
      std::size_t smallest = jobs, largest = 0;
      for (int i = 0; i < n; ++i) {
        const auto s = shard_jobs(jobs, i, n);
        smallest = std::min(smallest, s.size()), largest = std::max(largest, s.size());
        for (auto k : s) ++seen[k];
      }
      for (std::size_t k = 0; k < jobs; ++k) EXPECT_EQ(seen[k], 1) << "job " << k << " of " << jobs << ", " << n << " shards";
      EXPECT_LE(largest - std::min(smallest, largest), 1u);
    }
  EXPECT_EQ(parse_shard("2/5"), (std::pair<int, int>{2, 5}));
  for (const char* bad : {"5/5", "-1/3", "1/0", "1", "1/2x", ""}) EXPECT_THROW(parse_shard(bad), core::InputError) << bad;
}

}  // namespace
}  // namespace fovea::sweep
