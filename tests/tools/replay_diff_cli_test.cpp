// `fovea render` writes frames.jsonl (the gaze used per frame, poses, grid; timings apart)
// and `fovea replay-diff` compares two runs: two identical runs agree, a changed gaze or a
// missing image is a difference (exit 1), a directory without frames.jsonl is exit 2.
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
namespace fs = std::filesystem;

TEST(ReplayDiffCli, TwoRunsAgreeAndChangesAreFound) {
  const std::string a = temp_dir("replay-a"), b = temp_dir("replay-b");
  const std::string common = "render --display tiny --scene cornell --gaze synthetic:3 --frames 2 --quiet --out ";
  ASSERT_EQ(run_fovea(common + a).status, 0);
  ASSERT_EQ(run_fovea(common + b).status, 0);
  std::ifstream in(a + "/frames.jsonl");
  std::string line;
  std::size_t frames = 0;
  while (std::getline(in, line)) {
    const auto j = fovea::core::parse_json(line);
    EXPECT_EQ(j["frame"], frames);
    // The newest real sample behind the frame's fovea: measured at or before the frame's time.
    ASSERT_TRUE(j["gaze"]["sample_ns"].is_number()) << line;
    EXPECT_LE(j["gaze"]["sample_ns"].get<long long>(), j["t_ns"].get<long long>());
    EXPECT_EQ(j["grid"].size(), 2u);
    EXPECT_EQ(j["eye_poses"].size(), 2u);
    ++frames;
  }
  EXPECT_EQ(frames, 2u);
  // Deterministic fields only: two identical runs write identical bytes; timings apart.
  EXPECT_EQ(read_text(a + "/frames.jsonl"), read_text(b + "/frames.jsonl"));
  const auto times = fovea::core::parse_json(read_text(a + "/frame_times.jsonl").substr(0, read_text(a + "/frame_times.jsonl").find('\n')));
  EXPECT_EQ(times["frame"], 0);
  EXPECT_EQ(times["schema"], "fovea-timing");
  EXPECT_TRUE(times["gpu_ms"].contains("trace"));
  EXPECT_TRUE(times["cpu_ms"].contains("grid"));

  const auto same = run_fovea("replay-diff --json " + a + " " + b);
  ASSERT_EQ(same.status, 0) << same.out << same.err;
  EXPECT_EQ(fovea::core::parse_json(same.out)["images"].size(), 6u);

  // The gaze of frame 1 turned by ~0.06°: found; accepted with a looser tolerance.
  std::stringstream ss(read_text(b + "/frames.jsonl"));
  std::vector<std::string> lines;
  for (std::string l; std::getline(ss, l);) lines.push_back(l);
  auto j = fovea::core::parse_json(lines[1]);
  auto& d = j["used_gaze"]["left"];
  d[0] = d[0].get<double>() + 1e-3;
  lines[1] = j.dump();
  std::ofstream(b + "/frames.jsonl") << lines[0] << "\n" << lines[1] << "\n";
  const auto moved = run_fovea("replay-diff " + a + " " + b);
  EXPECT_EQ(moved.status, 1) << moved.out;
  EXPECT_NE(moved.out.find("frame 1.used_gaze.left"), std::string::npos) << moved.out;
  EXPECT_EQ(run_fovea("replay-diff --gaze-tol-deg 0.1 " + a + " " + b).status, 0);

  fs::remove(b + "/frame_0000_sbs.png");
  const auto missing = run_fovea("replay-diff --gaze-tol-deg 0.1 " + a + " " + b);
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.out.find("frame_0000_sbs.png: only in A"), std::string::npos) << missing.out;

  fs::remove(b + "/frames.jsonl");
  const auto bad = run_fovea("replay-diff " + a + " " + b);
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("frames.jsonl"), std::string::npos) << bad.err;
  fs::remove_all(a);
  fs::remove_all(b);
}
