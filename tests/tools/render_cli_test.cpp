// `fovea render`: the main job end to end on the tiny display — report.json with the
// issue's fields (finite), per-frame PNGs and the last frame's EXRs; bad input -> exit 2.
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"

#include "fovea/core/json.hpp"

using fovea::test::run_fovea;

namespace {

void expect_finite_numbers(const nlohmann::json& j, const std::string& where) {
  if (j.is_number()) {
    EXPECT_TRUE(std::isfinite(j.get<double>())) << where;
  } else if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) expect_finite_numbers(it.value(), where + "." + it.key());
  } else if (j.is_array()) {
    for (size_t i = 0; i < j.size(); ++i) expect_finite_numbers(j[i], where + "[" + std::to_string(i) + "]");
  }
}

TEST(RenderCli, ReportFramesAndExrOnTheTinyDisplay) {
  namespace fs = std::filesystem;
  const std::string dir = fovea::test::temp_dir("render");
  const auto r = run_fovea("render --display tiny --scene cornell --gaze synthetic:3 --frames 3 --reference 4 "
                           "--reference-cache off --stereo-share gather --quiet --out " + dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("VUID"), std::string::npos) << "validation messages:\n" << r.err;
  std::ifstream in(dir + "/report.json");
  const auto j = fovea::core::parse_json(in);
  EXPECT_EQ(j["frames"], 3);
  EXPECT_GT(j["samples_traced_per_eye"].get<double>(), 0);
  EXPECT_LT(j["samples_traced_per_eye"].get<double>(), 64 * 72);  // foveated: fewer than the pixels
  for (const char* k : {"trace", "reconstruct", "resolve", "total"}) EXPECT_TRUE(j["gpu_ms"].contains(k)) << k;
  // The Vulkan device and driver the timings come from.
  EXPECT_FALSE(j["device"]["name"].get<std::string>().empty());
  EXPECT_FALSE(j["device"]["driver"].get<std::string>().empty());
  // lavapipe's BMFR schedule (reconstruct::bmfr_schedule: a CPU device).
  if (j["device"]["name"].get<std::string>().starts_with("llvmpipe")) {
    EXPECT_EQ(j["device"]["bmfr_fit"]["workgroup"], 8);
    EXPECT_EQ(j["device"]["bmfr_fit"]["reduction"], "serial");
  }
  for (const char* k : {"gaze", "grid", "trace", "reconstruct", "resolve", "submit", "wait", "total"})
    EXPECT_GE(j["cpu_ms"].value(k, -1.0), 0.0) << "cpu_ms." << k;
  // Output apart from the frame: every frame is written (--png-every 1), so each is read back.
  EXPECT_FALSE(j["cpu_ms"].contains("readback"));
  EXPECT_EQ(j["output"]["frames_read_back"], 3);
  EXPECT_EQ(j["output"]["host_bytes_read_back"].get<std::int64_t>(), 3 * 2 * 64 * 72 * 16);
  EXPECT_GT(j["output"]["write_cpu_ms"].get<double>(), 0.0);
  EXPECT_GT(j["cpu_ms"]["total"].get<double>(), 0.0);
  // The device memory the frames held, per heap (the reference of the recovery curve, made
  // before them, apart).
  ASSERT_FALSE(j["device_memory"]["heaps"].empty());
  double held = 0;
  for (const auto& h : j["device_memory"]["heaps"]) {
    EXPECT_GE(h["peak_mib"].get<double>(), h["held_mib"].get<double>()) << h;
    EXPECT_LE(h["peak_mib"].get<double>(), h["size_mib"].get<double>()) << h;
    held += h["held_mib"].get<double>();
  }
  EXPECT_GT(held, 0.0);
  EXPECT_LE(j["device_memory"]["device_local_held_mib"].get<double>(), held + 0.05);
  EXPECT_GE(j["device_memory"]["device_local_peak_mib"].get<double>(),
            j["device_memory"]["device_local_held_mib"].get<double>());
  // The tiny preset's lens hides the view's corners: those cells are not traced.
  for (const char* eye : {"left", "right"}) EXPECT_GT(j["samples_hidden"][eye].get<double>(), 0) << eye;
  for (const char* eye : {"left", "right"}) {
    const auto& s = j["summary"][eye];
    for (const char* k : {"psnr", "fovea_psnr", "foveated_psnr", "ssim", "hdr_flip", "temporal_error", "bands"})
      EXPECT_TRUE(s.contains(k)) << eye << "." << k;
    EXPECT_TRUE(s["bands"].is_array());
    EXPECT_GT(s["bands"].size(), 3u);
  }
  expect_finite_numbers(j, "report");
  for (const char* f : {"frame_0002_left.png", "frame_0002_right.png", "frame_0002_sbs.png", "last_left.exr",
                        "last_right.exr"})
    EXPECT_TRUE(fs::exists(dir + "/" + f)) << f;
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << "temporary file left: " << e.path();
  fs::remove_all(dir);
}

// --no-cull traces the hidden area too: no cell is skipped for it, more cells are traced.
TEST(RenderCli, NoCullTracesTheHiddenArea) {
  namespace fs = std::filesystem;
  const std::string dir = fovea::test::temp_dir("render-cull");
  std::int64_t traced[2] = {0, 0};
  for (int cull = 0; cull < 2; ++cull) {
    const auto r = run_fovea(std::string("render --display tiny --scene cornell --gaze synthetic:3 --frames 1 --quiet ") +
                             "--png-every 0 --denoiser none " + (cull ? "" : "--no-cull ") + "--out " + dir);
    ASSERT_EQ(r.status, 0) << r.err;
    std::ifstream in(dir + "/report.json");
    const auto j = fovea::core::parse_json(in);
    EXPECT_EQ(j["config"]["cull_hidden_area"].get<bool>(), cull == 1);
    for (const char* eye : {"left", "right"})
      EXPECT_EQ(j["samples_hidden"][eye].get<std::int64_t>() > 0, cull == 1) << eye;
    traced[cull] = j["samples_traced_per_eye"].get<std::int64_t>();
  }
  EXPECT_LT(traced[1], traced[0]);
  fs::remove_all(dir);
}

TEST(RenderCli, BadInputExitsWithTwo) {
  const std::string dir = fovea::test::temp_dir("render-bad");
  for (const char* args : {"render --frames 0", "render --frames x", "render --distribution bogus",
                           "render --denoiser magic", "render --stereo-share both", "render --bmfr-precision fp8",
                           "render --scene /nonexistent/scene.gltf", "render --display nonexistent",
                           "render --gaze /nonexistent/gaze.csv", "render --budget 0"}) {
    const auto r = run_fovea(std::string(args) + " --quiet --out " + dir);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_FALSE(r.err.empty()) << args;
  }
  // An unknown driver choice is refused whatever else selects the driver.
  setenv("FOVEA_VK_DRIVER", "bogus", 1);
  const auto r = run_fovea("render --display tiny --frames 1 --quiet --out " + dir);
  unsetenv("FOVEA_VK_DRIVER");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("FOVEA_VK_DRIVER"), std::string::npos) << r.err;
  std::filesystem::remove_all(dir);
}

}  // namespace

namespace {

// Frames neither written nor in the flicker window (the last 8) stay on the device: the
// temporal error is measured there.
TEST(RenderCli, FramesNotWrittenAreNotReadBack) {
  namespace fs = std::filesystem;
  const std::string dir = fovea::test::temp_dir("render-resident");
  const auto r = run_fovea("render --display tiny --scene cornell --frames 12 --png-every 0 --quiet --out " + dir);
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream in(dir + "/report.json");
  const auto j = fovea::core::parse_json(in);
  EXPECT_EQ(j["output"]["frames_read_back"], 8);
  EXPECT_EQ(j["output"]["host_bytes_read_back"].get<std::int64_t>(), 8 * 2 * 64 * 72 * 16);
  EXPECT_DOUBLE_EQ(j["output"]["host_bytes_per_frame"].get<double>(), 8.0 * 2 * 64 * 72 * 16 / 12);
  for (const char* eye : {"left", "right"}) EXPECT_GT(j["summary"][eye]["temporal_error"].get<double>(), 0.0) << eye;
  // Only the last frame is written; the frame records carry the output times of the frames
  // that had output.
  EXPECT_TRUE(fs::exists(dir + "/frame_0011_sbs.png"));
  EXPECT_FALSE(fs::exists(dir + "/frame_0000_sbs.png"));
  std::ifstream times(dir + "/frame_times.jsonl");
  std::string line;
  int with_readback = 0;
  while (std::getline(times, line))
    with_readback += fovea::core::parse_json(line)["cpu_ms"].contains("output_readback");
  EXPECT_EQ(with_readback, 8);
  fs::remove_all(dir);
}

}  // namespace
