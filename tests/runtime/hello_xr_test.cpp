// End to end: Debian's hello_xr (OpenXR 1.0.20 sample) rendering with Vulkan on lavapipe
// against the Fovea runtime, headless, ended by FOVEA_EXIT_AFTER_FRAMES.
#include <filesystem>
#include <fstream>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"
#include "xr_process.hpp"

namespace fovea::test {
namespace {

constexpr int kFrames = 12;
constexpr int kPngEvery = 4;

std::vector<nlohmann::json> timing(const std::string& out) {
  std::vector<nlohmann::json> v;
  std::ifstream in(out + "/timing.jsonl");
  for (std::string line; std::getline(in, line);) v.push_back(fovea::core::parse_json(line));
  return v;
}

// Fraction of pixels that differ from the most common colour (hello_xr's background).
double foreground_fraction(const core::Image& img) {
  std::map<std::tuple<int, int, int>, int> hist;
  auto key = [](const glm::vec4& c) {
    return std::tuple<int, int, int>(int(c.x * 255 + 0.5f), int(c.y * 255 + 0.5f), int(c.z * 255 + 0.5f));
  };
  for (const auto& p : img.pixels) ++hist[key(p)];
  int mode = 0;
  for (const auto& [k, n] : hist) mode = std::max(mode, n);
  return 1.0 - double(mode) / double(img.pixels.size());
}

void expect_clean_output(const ProcessResult& r) {
  EXPECT_EQ(r.output.find("VUID-"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("Validation Error"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("[fovea-runtime] error"), std::string::npos) << r.output;
}

ProcessResult run_and_check(const std::string& graphics, std::map<std::string, std::string> extra_env = {}) {
  TempDir dir("hello_xr");
  auto env = runtime_env(dir.path(), kFrames, kPngEvery);
  for (auto& [k, v] : extra_env) env[k] = v;
  const ProcessResult r = run_process({FOVEA_HELLO_XR, "-g", graphics}, env, 120);
  EXPECT_FALSE(r.timed_out) << r.output;
  EXPECT_EQ(r.exit_code, 0) << r.output;
  if (r.exit_code != 0) return r;
  expect_clean_output(r);

  // Every frame logged, on the display clock: predicted display times one period apart.
  const auto frames = timing(dir.path());
  EXPECT_EQ(frames.size(), size_t(kFrames));
  if (frames.size() != size_t(kFrames)) return r;
  const std::int64_t period = 1'000'000'000 / 70;  // the "small" preset runs at 70 Hz
  for (size_t i = 0; i < frames.size(); ++i) {
    const auto& f = frames[i];
    EXPECT_EQ(f["frame"].get<std::int64_t>(), std::int64_t(i));
    if (i > 0) {
      const std::int64_t dt =
          f["predicted_display_ns"].get<std::int64_t>() - frames[i - 1]["predicted_display_ns"].get<std::int64_t>();
      EXPECT_NEAR(double(dt), double(period), 2.0);
    }
    EXPECT_LE(f["wait_call_ns"].get<std::int64_t>(), f["wait_return_ns"].get<std::int64_t>());
    EXPECT_LE(f["begin_ns"].get<std::int64_t>(), f["end_call_ns"].get<std::int64_t>());
    EXPECT_LE(f["end_call_ns"].get<std::int64_t>(), f["end_return_ns"].get<std::int64_t>());
    // The eye tracker was read for the frame at its wake time (lockstep pacing: one period
    // plus the 3 ms compositor budget before the display time): the newest 120 Hz sample
    // measured by the read time, never a later one (the runtime used to take the sample at
    // the display time, ahead of the read), received when measured (a synthetic tracker
    // without a tracker model). The source starts at the display epoch (frame 0's display
    // time): a read before it has no sample yet.
    const std::int64_t read_t = f["gaze_read_ns"].get<std::int64_t>();
    EXPECT_EQ(read_t, f["predicted_display_ns"].get<std::int64_t>() - period - 3'000'000);
    EXPECT_LE(read_t, f["end_call_ns"].get<std::int64_t>());
    if (f["gaze_sample_ns"].is_null()) {
      EXPECT_LT(read_t, frames[0]["predicted_display_ns"].get<std::int64_t>()) << f.dump();
    } else {
      const std::int64_t gaze_t = f["gaze_sample_ns"].get<std::int64_t>();
      EXPECT_GT(gaze_t, 0);
      EXPECT_LE(gaze_t, read_t);
      EXPECT_GT(gaze_t, read_t - 8'333'334);
      EXPECT_EQ(f["gaze_receive_ns"].get<std::int64_t>(), gaze_t);
    }
    EXPECT_EQ(f["composited"].get<bool>(), i % kPngEvery == 0);
    // Host time per stage: read-back happened exactly on the composited frames with layers.
    const auto& cpu = f["cpu_ms"];
    const bool read = f["composited"].get<bool>() && f["layers"].get<int>() > 0;
    EXPECT_EQ(cpu["readback"].get<double>() > 0, read) << f.dump();
    EXPECT_GE(cpu["gaze"].get<double>(), 0);
  }
  // hello_xr renders from its second frame on (the first one is not yet visible).
  EXPECT_EQ(frames[0]["layers"].get<int>(), 0);
  EXPECT_EQ(frames[kFrames - 1]["layers"].get<int>(), 1);

  // Panel images: hello_xr's cubes visible (not a constant image), the eyes differ (stereo).
  for (int f = 0; f < kFrames; ++f)
    for (const char* eye : {"left", "right"}) {
      char name[64];
      std::snprintf(name, sizeof name, "/panel_%06d_%s.png", f, eye);
      EXPECT_EQ(std::filesystem::exists(dir.path() + name), f % kPngEvery == 0) << name;
    }
  const core::Image left = core::read_png(dir.path() + "/panel_000008_left.png");
  const core::Image right = core::read_png(dir.path() + "/panel_000008_right.png");
  EXPECT_EQ(left.width, 320);
  EXPECT_EQ(left.height, 360);
  EXPECT_GT(foreground_fraction(left), 0.005);
  EXPECT_LT(foreground_fraction(left), 0.9);
  EXPECT_NE(left.pixels, right.pixels);

  // The runtime's log shows the session's path and the hidden area the compositor applied.
  const std::string log = read_text(dir.path() + "/runtime.log");
  EXPECT_NE(log.find("FOVEA_EXIT_AFTER_FRAMES=12 reached"), std::string::npos) << log;
  EXPECT_NE(log.find("hidden area"), std::string::npos) << log;
  EXPECT_NE(log.find("gaze"), std::string::npos) << log;
  return r;
}

TEST(HelloXr, Vulkan2) { run_and_check("Vulkan2"); }

TEST(HelloXr, Vulkan) { run_and_check("Vulkan"); }

// hello_xr under realtime pacing (the default outside these comparisons), with the panel
// composed every 4th frame making it late: every prediction is ahead of xrWaitFrame's return
// and on the vsync grid, no wait returns before its wake time, no frame is displayed before
// it was submitted.
TEST(HelloXr, RealtimePacing) {
  TempDir dir("hello_xr_rt");
  auto env = runtime_env(dir.path(), kFrames, kPngEvery);
  env["FOVEA_RUNTIME_PACING"] = "realtime";
  const ProcessResult r = run_process({FOVEA_HELLO_XR, "-g", "Vulkan2"}, env, 120);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  expect_clean_output(r);
  const auto frames = timing(dir.path());
  ASSERT_EQ(frames.size(), size_t(kFrames));
  const std::int64_t period = 14285714;   // 70 Hz ("small")
  const std::int64_t budget = 3'000'000;  // the compositor budget's 3 ms floor
  const auto t = [](const nlohmann::json& f, const char* k) { return f[k].get<std::int64_t>(); };
  for (size_t i = 0; i < frames.size(); ++i) {
    const auto& f = frames[i];
    EXPECT_GT(t(f, "predicted_display_ns"), t(f, "wait_return_ns")) << i;
    EXPECT_GE(t(f, "wait_return_ns"), t(f, "predicted_display_ns") - period - budget) << i;
    EXPECT_GE(t(f, "vsync_ns"), t(f, "end_call_ns") + budget) << i;
    EXPECT_GE(t(f, "vsync_ns"), t(f, "predicted_display_ns")) << i;
    if (i > 0) {
      const std::int64_t dt = t(f, "predicted_display_ns") - t(frames[i - 1], "predicted_display_ns");
      EXPECT_GE(dt, period - 1) << i;
      EXPECT_EQ(dt % period, 0) << i;  // on the vsync grid
    }
  }
}

// The Khronos core validation layer between hello_xr and the runtime reports nothing.
TEST(HelloXr, CoreValidationClean) {
  TempDir report("xr_cv");
  const std::string file = report.path() + "/core_validation.txt";
  const ProcessResult r = run_and_check("Vulkan2", {{"XR_ENABLE_API_LAYERS", "XR_APILAYER_LUNARG_core_validation"},
                            {"XR_CORE_VALIDATION_EXPORT_TYPE", "text"},
                            {"XR_CORE_VALIDATION_FILE_NAME", file},
                            {"XR_LOADER_DEBUG", "info"}});
  // The loader's own report (stderr, unbuffered) shows the layer was in the chain.
  EXPECT_NE(r.output.find("succeeded loading layer XR_APILAYER_LUNARG_core_validation"), std::string::npos)
      << "layer not active:\n" << r.output;
  const std::string text = read_text(file);
  EXPECT_EQ(text.find("VUID-"), std::string::npos) << text;
  EXPECT_EQ(text.find("VALID_ERROR"), std::string::npos) << text;
}

// Marker mode through the runtime's display stage: FOVEA_MARKER=periodic lights frames 0–3
// and 8–11 (4 on, 4 off); the composed panels (frames 0, 4, 8) show a white 24-pixel square
// in the top-right corner when lit and a black one when not, and marker.jsonl logs each
// event with the display time the timing log has for that frame.
TEST(HelloXr, MarkerOnThePanels) {
  TempDir dir("hello_xr_marker");
  auto env = runtime_env(dir.path(), kFrames, kPngEvery);
  env["FOVEA_MARKER"] = "periodic";
  env["FOVEA_MARKER_CORNER"] = "tr";
  env["FOVEA_MARKER_SIZE"] = "24";
  env["FOVEA_MARKER_FRAMES"] = "4";
  const ProcessResult r = run_process({FOVEA_HELLO_XR, "-g", "Vulkan2"}, env, 120);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  expect_clean_output(r);
  for (int f : {0, 4, 8}) {
    const bool lit = f != 4;
    char name[64];
    std::snprintf(name, sizeof name, "/panel_%06d_right.png", f);
    const core::Image img = core::read_png(dir.path() + name);
    ASSERT_EQ(img.width, 320);
    int inside = 0, white_outside = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const glm::vec4 c = img.at(x, y);
        const bool white = c.x == 1 && c.y == 1 && c.z == 1;
        if (x >= img.width - 24 && y < 24) inside += lit ? white : (c.x == 0 && c.y == 0 && c.z == 0);
        else white_outside += white;
      }
    EXPECT_EQ(inside, 24 * 24) << name;
    EXPECT_LT(white_outside, img.width * img.height / 2) << name;  // the scene is still there
  }
  const auto frames = timing(dir.path());
  ASSERT_EQ(frames.size(), size_t(kFrames));
  std::vector<nlohmann::json> events;
  std::ifstream in(dir.path() + "/marker.jsonl");
  for (std::string line; std::getline(in, line);) events.push_back(fovea::core::parse_json(line));
  ASSERT_EQ(events.size(), 2u);
  for (size_t i = 0; i < events.size(); ++i) {
    const std::int64_t f = events[i]["frame"].get<std::int64_t>();
    EXPECT_EQ(f, std::int64_t(8 * i));
    EXPECT_EQ(events[i]["displayed_ns"].get<std::int64_t>(), frames[size_t(f)]["vsync_ns"].get<std::int64_t>());
    EXPECT_TRUE(events[i]["event_sample_ns"].is_null());  // periodic: no gaze event behind it
  }
}

}  // namespace
}  // namespace fovea::test
