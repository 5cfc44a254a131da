// `fovea render`'s quality metrics and references: the report's tone-mapped, FLIP, fovea,
// foveated, per-band and flicker fields; more samples score better; a render compared with
// itself scores FLIP 0; the reference cache (second run reads it, a changed scene byte
// changes the key, `render` and `reference` share entries, damaged entries are rendered
// again); a sweep renders a reference shared by its jobs once.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"

#include "fovea/core/json.hpp"

namespace {

namespace fs = std::filesystem;
using fovea::test::run_fovea;
using nlohmann::json;

json read_json(const std::string& path) {
  std::ifstream in(path);
  return fovea::core::parse_json(in);
}

// A gaze recording that never moves: the scene, head and gaze are still.
std::string fixed_gaze(const std::string& dir) {
  const std::string path = dir + "/fixed.csv";
  std::ofstream(path) << "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n"
                         "0,combined,0.05,0.02,-1,1,1\n"
                         "10000000000,combined,0.05,0.02,-1,1,1\n";
  return path;
}

json render(const std::string& args, const std::string& out) {
  const auto r = run_fovea("render --display tiny --scene cornell --quiet --png-every 0 " + args + " --out " + out);
  EXPECT_EQ(r.status, 0) << args << "\n" << r.err;
  return read_json(out + "/report.json");
}

const char* kScores[] = {"psnr", "ssim", "rel_mse", "ldr_flip", "hdr_flip"};

TEST(RenderMetrics, ReportHasEveryScoreFiniteWithToneMapperAndFlicker) {
  const std::string dir = fovea::test::temp_dir("metrics");
  const json j = render("--frames 3 --gaze " + fixed_gaze(dir) + " --reference 8 --reference-cache " + dir + "/cache",
                        dir + "/r");
  EXPECT_NE(j["metrics"]["tone_mapper"].get<std::string>().find("ACES"), std::string::npos);
  EXPECT_EQ(j["metrics"]["exposure"], 0.0);
  EXPECT_GT(j["metrics"]["ppd"].get<double>(), 0.0);
  EXPECT_EQ(j["config"]["stereo_share"], "gather");  // sharing is on by default
  for (const char* eye : {"left", "right"}) {
    const json& s = j["summary"][eye];
    for (const char* prefix : {"", "fovea_", "foveated_"})
      for (const char* k : kScores) {
        const std::string name = std::string(prefix) + k;
        ASSERT_TRUE(s.contains(name)) << eye << "." << name;
        EXPECT_TRUE(std::isfinite(s[name].get<double>())) << eye << "." << name;
      }
    EXPECT_GE(s["hdr_flip"].get<double>(), 0.0);
    EXPECT_LE(s["hdr_flip"].get<double>(), 1.0);
    ASSERT_GT(s["bands"].size(), 3u);
    for (const json& b : s["bands"]) {
      EXPECT_EQ(b["e_max"].get<double>() - b["e_min"].get<double>(), 2.0);
      for (const char* k : kScores) EXPECT_TRUE(std::isfinite(b[k].get<double>())) << k;
    }
    // Three frames with the gaze held: flicker over all three.
    EXPECT_EQ(s["flicker_frames"], 3);
    for (const char* k : {"flicker", "fovea_flicker", "foveated_flicker"}) {
      EXPECT_TRUE(std::isfinite(s[k].get<double>())) << k;
      EXPECT_GT(s[k].get<double>(), 0.0) << k;  // a 1-spp path tracer is never still
    }
    EXPECT_EQ(j["metrics"]["reference"][eye]["spp"].get<int>(), 8);
  }
  fs::remove_all(dir);
}

// Eight frames accumulate eight samples per cell at a still gaze; one frame has one.
TEST(RenderMetrics, MoreSamplesScoreBetter) {
  const std::string dir = fovea::test::temp_dir("metrics-spp");
  const std::string common = "--denoiser none --distribution cartesian --gaze " + fixed_gaze(dir) +
                             " --reference 64 --reference-cache " + dir + "/cache";
  const json one = render("--frames 1 " + common, dir + "/one");
  const json eight = render("--frames 8 " + common, dir + "/eight");
  for (const char* eye : {"left", "right"}) {
    const json &a = one["summary"][eye], &b = eight["summary"][eye];
    EXPECT_GT(b["psnr"].get<double>(), a["psnr"].get<double>() + 1.0) << eye;
    EXPECT_GT(b["fovea_psnr"].get<double>(), a["fovea_psnr"].get<double>()) << eye;
    EXPECT_LT(b["hdr_flip"].get<double>(), a["hdr_flip"].get<double>()) << eye;
    EXPECT_LT(b["foveated_ldr_flip"].get<double>(), a["foveated_ldr_flip"].get<double>()) << eye;
    EXPECT_LT(b["rel_mse"].get<double>(), a["rel_mse"].get<double>()) << eye;
  }
  // The second render found both eyes' references in the cache.
  EXPECT_FALSE(one["metrics"]["reference"]["left"]["cached"].get<bool>());
  EXPECT_TRUE(eight["metrics"]["reference"]["left"]["cached"].get<bool>());
  EXPECT_EQ(one["metrics"]["reference"]["left"]["key"], eight["metrics"]["reference"]["left"]["key"]);
  fs::remove_all(dir);
}

// A render is deterministic: its own last frame, passed as the reference, scores identical.
TEST(RenderMetrics, ARenderAgainstItselfScoresFlipZero) {
  const std::string dir = fovea::test::temp_dir("metrics-self");
  const std::string args = "--frames 2 --gaze synthetic:3 --reference 4 --reference-cache off";
  render(args, dir + "/a");
  for (const char* eye : {"left", "right"})
    fs::copy_file(dir + "/a/last_" + eye + ".exr", dir + "/a/reference_" + eye + ".exr",
                  fs::copy_options::overwrite_existing);
  const json j = render("--frames 2 --gaze synthetic:3 --reference " + dir + "/a", dir + "/b");
  for (const char* eye : {"left", "right"}) {
    const json& s = j["summary"][eye];
    for (const char* prefix : {"", "fovea_", "foveated_"}) {
      EXPECT_EQ(s[std::string(prefix) + "hdr_flip"].get<double>(), 0.0) << eye << prefix;
      EXPECT_EQ(s[std::string(prefix) + "ldr_flip"].get<double>(), 0.0) << eye << prefix;
      EXPECT_EQ(s[std::string(prefix) + "psnr"].get<double>(), 100.0) << eye << prefix;
    }
  }
  // A reference of another scene is refused before rendering, naming the file.
  const auto r = run_fovea("render --display tiny --scene glossy-spheres --frames 1 --quiet --reference " + dir +
                           "/a --out " + dir + "/c");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("reference_left.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/c/report.json"));
  fs::remove_all(dir);
}

TEST(ReferenceCache, SecondRunReadsTheCacheAndASceneByteChangesTheKey) {
  const std::string dir = fovea::test::temp_dir("refcache");
  const std::string scene = dir + "/quad.obj";
  std::ofstream(scene) << "v -1 -1 -3\nv 1 -1 -3\nv 1 1 -3\nv -1 1 -3\nf 1 2 3\nf 1 3 4\n";
  auto reference = [&](const std::string& out) {
    const auto r = run_fovea("reference --display tiny --scene " + scene + " --spp 4 --batch 2 --quiet --reference-cache " +
                             dir + "/cache --out " + dir + "/" + out);
    EXPECT_EQ(r.status, 0) << r.err;
    return fovea::core::parse_json(r.out);
  };
  const json first = reference("a.exr"), second = reference("b.exr");
  EXPECT_FALSE(first["cached"].get<bool>());
  EXPECT_TRUE(second["cached"].get<bool>());
  EXPECT_EQ(first["key"], second["key"]);
  EXPECT_EQ(second["spp"], 4);
  // The entry and the outputs record their key.
  EXPECT_TRUE(fs::exists(dir + "/cache/" + first["key"].get<std::string>() + ".exr"));
  EXPECT_EQ(read_json(dir + "/b.json")["key"], first["key"]);
  std::ofstream(scene, std::ios::app) << "#\n";  // one more byte, same geometry
  const json changed = reference("c.exr");
  EXPECT_FALSE(changed["cached"].get<bool>());
  EXPECT_NE(changed["key"], first["key"]);
  // Other settings, other key.
  const auto r = run_fovea("reference --display tiny --scene " + scene + " --spp 4 --batch 2 --bounces 1 --quiet " +
                           "--reference-cache " + dir + "/cache --out " + dir + "/d.exr");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(fovea::core::parse_json(r.out)["key"], changed["key"]);
  fs::remove_all(dir);
}

// `fovea reference` and `fovea render --reference SPP` share defaults, keys and cache
// entries, in both directions (the render with --bounces auto traces the reference's full
// global illumination); the render's reference error is part of the key.
TEST(ReferenceCache, RenderAndReferenceCommandsReuseEachOthersEntries) {
  const std::string dir = fovea::test::temp_dir("refshare");
  const std::string cache = " --reference-cache " + dir + "/cache";
  const auto reference = [&](const std::string& eye, const std::string& extra) {
    const auto r = run_fovea("reference --display tiny --scene cornell --eye " + eye + " --spp 8 --quiet" + extra + cache +
                             " --out " + dir + "/" + eye + ".exr");
    EXPECT_EQ(r.status, 0) << r.err;
    return fovea::core::parse_json(r.out);
  };
  const json left = reference("left", "");
  EXPECT_FALSE(left["cached"].get<bool>());
  const json a = render("--frames 1 --gaze synthetic:3 --bounces auto --reference 8" + cache, dir + "/a");
  const json& ref = a["metrics"]["reference"];
  EXPECT_TRUE(ref["left"]["cached"].get<bool>()) << "render did not reuse the reference command's entry";
  EXPECT_EQ(ref["left"]["key"], left["key"]);
  EXPECT_FALSE(ref["right"]["cached"].get<bool>());
  // The settings the key hashes, reported: the albedo rule's bounces, the default error.
  EXPECT_EQ(ref["left"]["settings"]["bounces"], left["bounces"]);
  EXPECT_EQ(ref["left"]["settings"]["rr_start"], left["rr_start"]);
  EXPECT_EQ(ref["left"]["settings"]["until_pixel_rel_error"].get<double>(), 0.02);
  // The other way round: the right eye, rendered by `render`, is read by `reference`.
  const json right = reference("right", " --until-pixel-rel-error 0.02");
  EXPECT_TRUE(right["cached"].get<bool>());
  EXPECT_EQ(right["key"], ref["right"]["key"]);
  // Another error target is another reference.
  const json b = render("--frames 1 --gaze synthetic:3 --bounces auto --reference 8 --reference-error 0.05" + cache,
                        dir + "/b");
  EXPECT_FALSE(b["metrics"]["reference"]["left"]["cached"].get<bool>());
  EXPECT_NE(b["metrics"]["reference"]["left"]["key"], left["key"]);
  EXPECT_EQ(b["metrics"]["reference"]["left"]["settings"]["until_pixel_rel_error"].get<double>(), 0.05);
  fs::remove_all(dir);
}

// The scores compare the same light transport: the default render (one bounce) against a
// one-bounce reference (the entry `fovea reference --bounces 1 --rr-start 1000` makes), full
// GI as its own labelled score, a DIR reference of another transport scored with a warning;
// lens-hidden pixels are counted and not scored; FLIP's filters said to be off at tiny.
TEST(RenderTransport, ScoresCompareTheSameLightTransport) {
  const std::string dir = fovea::test::temp_dir("transport");
  const std::string cache = " --reference-cache " + dir + "/cache";
  const auto r = run_fovea("reference --display tiny --scene cornell --eye left --spp 8 --bounces 1 --rr-start 1000 "
                           "--until-pixel-rel-error 0.02 --quiet" + cache + " --out " + dir + "/one.exr");
  ASSERT_EQ(r.status, 0) << r.err;
  const json one = fovea::core::parse_json(r.out);
  const json a = render("--frames 2 --gaze synthetic:3 --reference 8 --full-gi-score" + cache, dir + "/a");
  const json& t = a["transport"];
  EXPECT_EQ(t["render"]["bounces"], 1);
  EXPECT_TRUE(t["render"]["rr_start"].is_null());
  EXPECT_EQ(t["reference"]["bounces"], 1);
  EXPECT_TRUE(t["matched"].get<bool>());
  EXPECT_GT(t["full_gi"]["bounces"].get<int>(), 1);  // the albedo rule's
  const json& ref = a["metrics"]["reference"]["left"];
  EXPECT_TRUE(ref["cached"].get<bool>()) << "the one-bounce entry of `fovea reference` was not reused";
  EXPECT_EQ(ref["key"], one["key"]);
  EXPECT_NE(ref["full_gi"]["key"], ref["key"]);
  const json& s = a["summary"]["left"];
  ASSERT_TRUE(s.contains("full_gi"));
  EXPECT_TRUE(s["full_gi"]["hdr_flip"].is_number());
  EXPECT_NE(s["full_gi"]["hdr_flip"], s["hdr_flip"]);
  EXPECT_TRUE(fs::exists(dir + "/a/reference_left_full_gi.exr"));
  EXPECT_GT(a["metrics"]["hidden_pixels"]["left"].get<long>(), 0);
  EXPECT_FALSE(a["metrics"]["flip_filters"]["active"].get<bool>());
  // With --bounces auto the full-GI score is the matched one.
  const json b = render("--frames 2 --gaze synthetic:3 --bounces auto --reference 8 --full-gi-score" + cache, dir + "/b");
  EXPECT_EQ(b["summary"]["left"]["full_gi"]["hdr_flip"], b["summary"]["left"]["hdr_flip"]);
  // A directory of full-GI references scored by a one-bounce render: said, not hidden.
  const auto c = run_fovea("render --display tiny --scene cornell --quiet --png-every 0 --frames 2 --gaze synthetic:3 "
                           "--reference " + dir + "/b --out " + dir + "/c");
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_NE(c.err.find("compare different light transport"), std::string::npos) << c.err;
  EXPECT_FALSE(read_json(dir + "/c/report.json")["transport"]["matched"].get<bool>());
  // Bad values name the option.
  const auto bad = run_fovea("render --display tiny --scene cornell --quiet --frames 1 --bounces 300 --out " + dir + "/d");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--bounces"), std::string::npos) << bad.err;
  fs::remove_all(dir);
}

// The saccade recovery curve: a 32° gaze step (250 Hz samples, read without prediction)
// gives one landing of the asked frames, at the frame the grid reached the new gaze, with
// finite scores; still frames give none; it needs a whole-view reference.
TEST(RenderRecovery, AGazeStepGivesOneLandingCurve) {
  const std::string dir = fovea::test::temp_dir("recovery");
  const std::string step = dir + "/step.csv";
  {
    std::ofstream out(step);
    out << "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n";
    const double s = std::sin(16 * M_PI / 180), c = std::cos(16 * M_PI / 180);
    for (int i = 0; i < 250; ++i) {
      const long long t = i * 4'000'000LL;
      out << t << ",combined," << (t < 100'000'000 ? -s : s) << ",0," << -c << ",1,1\n";
    }
  }
  const json a = render("--frames 12 --gaze " + step + "?predict=none --reference 8 --recovery-frames 4"
                        " --reference-cache " + dir + "/cache", dir + "/a");
  const json& r = a["recovery"];
  ASSERT_EQ(r["landings"].size(), 1u) << r.dump();
  const json& l = r["landings"][0];
  EXPECT_EQ(l["frame"], 7);  // 100 ms at 70 Hz: frame 7 (100.0 ms) is the first after the step
  EXPECT_NEAR(l["amplitude_deg"].get<double>(), 32.0, 0.5);
  ASSERT_EQ(l["fovea_hdr_flip"].size(), 4u);
  for (const json& v : l["fovea_hdr_flip"]) EXPECT_TRUE(v.is_number() && v.get<double>() > 0 && v.get<double>() < 1);
  EXPECT_EQ(r["incomplete"], 0);
  EXPECT_EQ(r["mean_fovea_hdr_flip"].size(), 4u);
  // A still gaze: no landing.
  const json b = render("--frames 4 --gaze " + fixed_gaze(dir) + " --reference 8 --reference-cache " + dir + "/cache",
                        dir + "/b");
  EXPECT_EQ(b["recovery"]["landings"].size(), 0u);
  EXPECT_TRUE(b["recovery"]["mean_fovea_hdr_flip"].is_null());
  // Needs a whole-view reference.
  const auto bad = run_fovea("render --display tiny --scene cornell --quiet --frames 2 --recovery-frames 4 --out " + dir +
                             "/c");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("--recovery-frames"), std::string::npos) << bad.err;
  fs::remove_all(dir);
}

// A damaged entry (truncated image, unreadable or foreign description) is reported on
// stderr, rendered again and replaced; the run succeeds.
TEST(ReferenceCache, DamagedEntriesAreReportedAndRenderedAgain) {
  const std::string dir = fovea::test::temp_dir("refdamage");
  const std::string args = "reference --display tiny --scene cornell --spp 4 --quiet --reference-cache " + dir +
                           "/cache --out " + dir + "/out.exr";
  const auto first = run_fovea(args);
  ASSERT_EQ(first.status, 0) << first.err;
  const json made = fovea::core::parse_json(first.out);
  const std::string entry = dir + "/cache/" + made["key"].get<std::string>();
  const auto damage = [&](const std::string& file, const std::string& bytes) {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
    const auto r = run_fovea(args);
    EXPECT_EQ(r.status, 0) << file << ": " << r.err;
    EXPECT_NE(r.err.find("damaged reference cache entry"), std::string::npos) << file << ": " << r.err;
    EXPECT_NE(r.err.find(made["key"].get<std::string>()), std::string::npos) << r.err;
    const json j = fovea::core::parse_json(r.out);
    EXPECT_FALSE(j["cached"].get<bool>()) << file;
    EXPECT_EQ(j["key"], made["key"]);
    EXPECT_EQ(j["mean_rgb"], made["mean_rgb"]) << "the same seeds render the same reference";
    // Replaced: the next run reads it without complaint.
    const auto again = run_fovea(args);
    EXPECT_TRUE(fovea::core::parse_json(again.out)["cached"].get<bool>()) << file << ": " << again.err;
    EXPECT_EQ(again.err.find("damaged"), std::string::npos) << again.err;
  };
  damage(entry + ".exr", "not an image");
  damage(entry + ".json", "{\"key\": ");
  damage(entry + ".json", R"({"format": "fovea-reference", "key": "0123456789abcdef", "identity": {}})");
  fs::remove_all(dir);
}

TEST(SweepSharedReference, TwoJobsOnOneSceneRenderTheReferenceOnce) {
  const std::string dir = fovea::test::temp_dir("sweep-ref");
  std::ofstream(dir + "/sweep.json") << R"({"scenes": "cornell", "displays": "tiny", "frames": 1, "gaze": "synthetic:3",
    "distribution": "visual-polar", "budget": [0.2, 0.3], "reference": 4, "reference-cache": "off"})";
  ASSERT_EQ(run_fovea("sweep plan " + dir + "/sweep.json --out " + dir + "/plan.jsonl").status, 0);
  const auto r = run_fovea("sweep run " + dir + "/plan.jsonl --jobs 1 --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  int shared = 0;
  for (const auto& e : fs::directory_iterator(dir + "/shared")) {
    ++shared;
    EXPECT_TRUE(fs::exists(e.path() / "reference_left.json"));
  }
  EXPECT_EQ(shared, 1);
  std::string key;
  int jobs = 0;
  for (const auto& e : fs::directory_iterator(dir + "/jobs")) {
    const json j = read_json((e.path() / "report.json").string());
    const json& ref = j["metrics"]["reference"]["left"];
    EXPECT_TRUE(ref["cached"].get<bool>()) << "the job rendered its own reference";
    if (key.empty()) key = ref["key"];
    EXPECT_EQ(ref["key"], key);
    EXPECT_FALSE(fs::exists(e.path() / "reference_left.exr"));
    ++jobs;
  }
  EXPECT_EQ(jobs, 2);
  fs::remove_all(dir);
}

// Budgets the distribution cannot meet exit 2 naming what it reaches; linear fall-off and
// Visual-Polar at a high budget render and trace it.
TEST(RenderBudget, RefusedBudgetsExitTwoAndLinearFalloffRenders) {
  const std::string dir = fovea::test::temp_dir("budget");
  for (const auto& [args, says] : {std::pair{"--distribution linear-falloff --budget 0.05", "reaches no less than"},
                                   std::pair{"--distribution cartesian --budget 0.5", "cartesian-uniform"}}) {
    const auto r = run_fovea(std::string("render --display tiny --frames 1 --quiet ") + args + " --out " + dir + "/x");
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
  }
  // Visual-Polar past one cap's limit (0.9 of `tiny`'s pixels; it was refused, "reaches at most
  // 0.49"): its cap follows the rings' own pixels (docs/visual-polar.md).
  const json vp = render("--frames 1 --distribution visual-polar --budget 0.9", dir + "/vp");
  EXPECT_GT(vp["samples_traced_per_eye"].get<double>(), 0.75 * 0.9 * 64 * 72);
  const json j = render("--frames 1 --gaze synthetic:3 --distribution linear-falloff --budget 0.5", dir + "/lf");
  EXPECT_EQ(j["config"]["distribution"], "linear-falloff");
  // Traced: the kept cells minus the lens' hidden ones, so at most the budget (+5%).
  EXPECT_LT(j["samples_traced_per_eye"].get<double>(), 1.05 * 0.5 * 64 * 72);
  EXPECT_GT(j["samples_traced_per_eye"].get<double>(), 0.3 * 64 * 72);
  fs::remove_all(dir);
}

// A window reference scores the fovea and the bands whose pixels and SSIM/FLIP
// neighbourhoods it holds exactly as the whole view's reference with the same samples (HDR-FLIP
// aside: its exposure range comes from the window); the other bands, the whole image and the
// acuity-weighted scores are null with notes. A whole-view entry serves a window request.
TEST(ReferenceWindow, BandsInsideScoreAsWithTheWholeReferenceAndTheOthersAreMissing) {
  const std::string dir = fovea::test::temp_dir("refwindow");
  const std::string common = "--frames 2 --gaze " + fixed_gaze(dir) + " --reference 4 --reference-error 0";
  const json whole = render(common + " --reference-cache " + dir + "/cache", dir + "/whole");
  const json served = render(common + " --reference-window 40 --reference-cache " + dir + "/cache", dir + "/served");
  const json part = render(common + " --reference-window 40 --reference-cache off", dir + "/part");
  for (const char* eye : {"left", "right"}) {
    const json& wref = whole["metrics"]["reference"][eye];
    EXPECT_TRUE(wref["window"].is_null());
    EXPECT_EQ(wref["hdr_flip_exposures"]["from"], "whole image");
    const json& sref = served["metrics"]["reference"][eye];
    EXPECT_TRUE(sref["cached"].get<bool>()) << eye;
    EXPECT_EQ(sref["key"], wref["key"]);
    EXPECT_TRUE(sref["window"].is_null());
    EXPECT_EQ(served["summary"][eye]["psnr"], whole["summary"][eye]["psnr"]);

    const json& pref = part["metrics"]["reference"][eye];
    EXPECT_FALSE(pref["cached"].get<bool>());
    EXPECT_NE(pref["key"], wref["key"]);
    ASSERT_EQ(pref["window"].size(), 1u);
    EXPECT_EQ(pref["window"][0]["radius_deg"].get<double>(), 40.0);
    EXPECT_EQ(pref["hdr_flip_exposures"]["from"], "window");
    const json& s = part["summary"][eye];
    const json& w = whole["summary"][eye];
    // Centred on the scored gaze.
    const json& g = s["gaze"];
    const double len = std::hypot(g[0].get<double>(), g[1].get<double>(), g[2].get<double>());
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(pref["window"][0]["centre"][k].get<double>(), g[k].get<double>() / len, 1e-12);
    for (const char* prefix : {"", "foveated_"})
      for (const char* k : kScores) EXPECT_TRUE(s[std::string(prefix) + k].is_null()) << eye << " " << prefix << k;
    EXPECT_TRUE(s["linear_psnr"].is_null());
    ASSERT_TRUE(s.contains("quality_notes"));
    EXPECT_NE(s["quality_notes"][0].get<std::string>().find("window"), std::string::npos);
    for (const char* k : {"psnr", "ssim", "rel_mse", "ldr_flip"})
      EXPECT_EQ(s[std::string("fovea_") + k], w[std::string("fovea_") + k]) << eye << " fovea_" << k;
    ASSERT_EQ(s["bands"].size(), w["bands"].size());
    int scored = 0, missing = 0;
    for (std::size_t b = 0; b < s["bands"].size(); ++b) {
      const json &pb = s["bands"][b], &wb = w["bands"][b];
      EXPECT_EQ(pb["e_min"], wb["e_min"]);
      EXPECT_EQ(pb["pixels"], wb["pixels"]);
      if (pb["psnr"].is_null()) {
        ++missing;
        for (const char* k : kScores) EXPECT_TRUE(pb[k].is_null()) << k;
        EXPECT_NE(pb["missing"].get<std::string>().find("lacks pixels of this band"), std::string::npos);
        continue;
      }
      ++scored;
      EXPECT_EQ(missing, 0) << "a band inside follows a missing one";
      for (const char* k : {"psnr", "ssim", "rel_mse", "ldr_flip"}) EXPECT_EQ(pb[k], wb[k]) << eye << " band " << b << " " << k;
      EXPECT_GE(pb["hdr_flip"].get<double>(), 0.0);
      EXPECT_LE(pb["hdr_flip"].get<double>(), 1.0);
    }
    // tiny: 0.47 pixels per degree, so SSIM's 5-pixel margin is ~11 deg of the 40.
    EXPECT_GE(scored, 3) << eye;
    EXPECT_GE(missing, 10) << eye;
  }
  // The window references the render wrote, read back as a directory, score the same.
  const json again = render("--frames 2 --gaze " + fixed_gaze(dir) + " --reference " + dir + "/part", dir + "/again");
  EXPECT_EQ(again["summary"], part["summary"]);
  fs::remove_all(dir);
}

// The window is part of the key: the same window again reads the cache, another window or
// the whole view renders; an entry of the whole view serves a window, never the reverse.
TEST(ReferenceCache, TheWindowIsPartOfTheKeyAndOnlyTheWholeViewServesWindows) {
  const std::string dir = fovea::test::temp_dir("refwinkey");
  const auto reference = [&](const std::string& out, const std::string& window) {
    const auto r = run_fovea("reference --display tiny --scene cornell --spp 4 --quiet --reference-cache " + dir +
                             "/cache --out " + dir + "/" + out + (window.empty() ? "" : " --window '" + window + "'"));
    EXPECT_EQ(r.status, 0) << window << ": " << r.err;
    return fovea::core::parse_json(r.out);
  };
  const json a = reference("a.exr", "0,0,-1@30");
  EXPECT_FALSE(a["cached"].get<bool>());
  EXPECT_EQ(a["window"][0]["radius_deg"].get<double>(), 30.0);
  EXPECT_GT(a["pixels"].get<int>(), 0);
  EXPECT_LT(a["pixels"].get<int>(), 64 * 72);
  EXPECT_EQ(read_json(dir + "/a.json")["identity"]["window"], a["window"]);
  const json again = reference("a2.exr", "0,0,-2@30");  // the same direction, another length
  EXPECT_TRUE(again["cached"].get<bool>());
  EXPECT_EQ(again["key"], a["key"]);
  const json wider = reference("b.exr", "0,0,-1@31");
  EXPECT_FALSE(wider["cached"].get<bool>());
  EXPECT_NE(wider["key"], a["key"]);
  const json two = reference("c.exr", "0,0,-1@30;px:0,0@10");
  EXPECT_FALSE(two["cached"].get<bool>());
  EXPECT_EQ(two["window"].size(), 2u);
  EXPECT_GT(two["pixels"].get<int>(), a["pixels"].get<int>());
  const json whole = reference("w.exr", "");
  EXPECT_FALSE(whole["cached"].get<bool>()) << "a window served the whole view";
  EXPECT_TRUE(whole["window"].is_null());
  EXPECT_EQ(whole["pixels"].get<int>(), 64 * 72);
  EXPECT_FALSE(read_json(dir + "/w.json")["identity"].contains("window"));
  for (const json& k : {a["key"], wider["key"], two["key"]}) EXPECT_NE(whole["key"], k);
  const json served = reference("d.exr", "0.1,0,-1@20");
  EXPECT_TRUE(served["cached"].get<bool>());
  EXPECT_EQ(served["key"], whole["key"]);
  EXPECT_TRUE(served["window"].is_null());
  fs::remove_all(dir);
}

TEST(ReferenceWindow, BadWindowsExitTwoNamingTheOption) {
  const std::string dir = fovea::test::temp_dir("refwinbad");
  for (const char* spec : {"0,0,-1@0", "0,0,-1@-2", "0,0,-1@nan", "0,0,-1@200", "nan,0,-1@5", "0,0,0@5", "0,0,1@10",
                           "px:-400,-400@2", "0,0@5", "0,0,-1", "x,0,-1@5", "0,0,-1@5;0,0,1@5", ""}) {
    const auto r = run_fovea("reference --display tiny --scene cornell --spp 1 --quiet --reference-cache off --window '" +
                             std::string(spec) + "' --out " + dir + "/x.exr");
    EXPECT_EQ(r.status, 2) << spec;
    EXPECT_NE(r.err.find("--window"), std::string::npos) << spec << ": " << r.err;
  }
  EXPECT_FALSE(fs::exists(dir + "/x.exr"));
  for (const std::string& args : std::vector<std::string>{"--reference 4 --reference-window 0", "--reference 4 --reference-window nan",
                                 "--reference 4 --reference-window=-5", "--reference 4 --reference-window 200",
                                 "--reference-window 10", "--reference " + dir + " --reference-window 10"}) {
    const auto r = run_fovea("render --display tiny --scene cornell --frames 1 --quiet --reference-cache off " + args +
                             " --out " + dir + "/r");
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_NE(r.err.find("--reference-window"), std::string::npos) << args << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir + "/r/report.json")) << args;
  }
  fs::remove_all(dir);
}

}  // namespace
