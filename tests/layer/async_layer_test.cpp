// The layer's asynchronous path tracing, in-process on the Fovea runtime: an application that
// pipelines its frames on two threads (xrWaitFrame on one, xrBeginFrame/xrEndFrame on the
// other) through the layer with the Cornell box, the render thread slowed down by the test
// hook FOVEA_LAYER_TEST_RENDER_DELAY_MS. Structural, not timed: the application's frames
// keep ending while one path-traced frame is in the works, each displayed frame's record
// names the traced frame it showed, and the session tears down while the thread is busy.
// Run with either compositor: on the GPU no application image is ever copied to the host.
#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <sched.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "xr_fixture.hpp"
#include "xr_process.hpp"

#include "fovea/core/json.hpp"

namespace fovea::test {
namespace {

constexpr const char* kVariables[] = {"XR_API_LAYER_PATH", "XR_ENABLE_API_LAYERS", "FOVEA_LAYER_OUT",
                                      "FOVEA_LAYER_LOG_FILE", "FOVEA_SCENE", "FOVEA_LAYER_SCENE",
                                      "XDG_CONFIG_HOME", "FOVEA_LAYER_RENDER", "FOVEA_LAYER_TEST_RENDER_DELAY_MS",
                                      "FOVEA_LAYER_COMPOSITOR", "FOVEA_LAYER_RENDER_PRIORITY", "FOVEA_LAYER_HANDOVER",
                                      "VK_ADD_LAYER_PATH", "VK_INSTANCE_LAYERS"};

// A thread of this process as /proc/self/task/<tid>/stat shows it.
struct ThreadInfo {
  std::string name;
  int nice = 0;
  int policy = 0;  // SCHED_OTHER 0, SCHED_IDLE 5
};
std::map<int, ThreadInfo> threads() {
  std::map<int, ThreadInfo> out;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) {
    std::string stat;
    try {
      std::ifstream in(entry.path() / "stat");
      stat.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    } catch (const std::ios_base::failure&) {
      // A thread that ends between the open and the read fails the read with ESRCH, which
      // libstdc++'s filebuf throws whatever the stream's exception mask.
      continue;
    }
    const auto open = stat.find('('), close = stat.rfind(')');
    if (open == std::string::npos || close == std::string::npos) continue;  // the thread ended meanwhile
    ThreadInfo t;
    t.name = stat.substr(open + 1, close - open - 1);
    // After the name: field 3 (state) onwards; nice is field 19, policy field 41 (proc(5)).
    std::istringstream rest(stat.substr(close + 2));
    std::vector<std::string> f{std::istream_iterator<std::string>(rest), std::istream_iterator<std::string>()};
    if (f.size() < 39) continue;
    t.nice = std::stoi(f[16]);
    t.policy = std::stoi(f[38]);
    out[std::stoi(entry.path().filename().string())] = t;
  }
  return out;
}

// The records written so far: whole lines only, since the layer's log thread may be writing
// the last one while a running session is read (a half line threw out of the test body,
// and the waiter thread, still joinable, aborted the test binary).
std::vector<nlohmann::json> records(const std::string& file) {
  std::vector<nlohmann::json> out;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && !in.eof()) out.push_back(fovea::core::parse_json(line));
  return out;
}

// The parameter: how the traced frame reaches the application: "application-device" (the GPU
// composition, the path tracer on the application's device with a queue of its own: lavapipe
// gets a spare queue from tests/layer/spare_queue_layer.cpp), "shared-memory" (the GPU
// composition, the slots written by the layer's device), "host-slot" (the GPU composition,
// FOVEA_LAYER_HANDOVER=host) or "host" (FOVEA_LAYER_COMPOSITOR=host).
class AsyncLayer : public XrTest, public ::testing::WithParamInterface<const char*> {
 protected:
  void SetUp() override {
    XrTest::SetUp();  // the tiny display
    out_ = std::make_unique<TempDir>("async-layer");
    setenv("XDG_CONFIG_HOME", (out_->path() + "/no-config").c_str(), 1);
    setenv("XR_API_LAYER_PATH", FOVEA_LAYER_EXPLICIT_DIR, 1);
    setenv("XR_ENABLE_API_LAYERS", "XR_APILAYER_FOVEA_path_tracing", 1);
    setenv("FOVEA_LAYER_OUT", out_->path().c_str(), 1);
    setenv("FOVEA_LAYER_LOG_FILE", (out_->path() + "/layer.log").c_str(), 1);
    setenv("FOVEA_SCENE", "cornell", 1);
    unsetenv("FOVEA_LAYER_SCENE");
    unsetenv("FOVEA_LAYER_RENDER");  // the default: asynchronous
    unsetenv("FOVEA_LAYER_RENDER_PRIORITY");  // the default: nice 19
    const std::string handover = GetParam();
    setenv("FOVEA_LAYER_COMPOSITOR", handover == "host" ? "host" : "gpu", 1);
    const bool shared = handover == "shared-memory" || handover == "application-device";
    setenv("FOVEA_LAYER_HANDOVER", shared ? "shared" : "host", 1);
    if (handover == "application-device") {
      setenv("VK_ADD_LAYER_PATH", FOVEA_TEST_SPARE_QUEUE_DIR, 1);
      setenv("VK_INSTANCE_LAYERS", "VK_LAYER_FOVEA_test_spare_queue", 1);
    }
    // Far slower than a frame interval: the application must not notice.
    setenv("FOVEA_LAYER_TEST_RENDER_DELAY_MS", "700", 1);
  }
  void TearDown() override {
    for (XrSwapchain sc : eye_)
      if (sc) xrDestroySwapchain(sc);
    XrTest::TearDown();
    for (const char* k : kVariables) unsetenv(k);
  }
  std::string timing() const { return out_->path() + "/layer_timing.jsonl"; }

  void cycle(XrSwapchain sc) {
    uint32_t index = 0;
    ASSERT_EQ(xrAcquireSwapchainImage(sc, nullptr, &index), XR_SUCCESS);
    XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
    wi.timeout = XR_INFINITE_DURATION;
    ASSERT_EQ(xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
    ASSERT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
  }

  std::unique_ptr<TempDir> out_;
  XrSwapchain eye_[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
};

TEST_P(AsyncLayer, PipelinedFramesOnTwoThreadsNeverWaitForTheRenderThread) {
  const std::string handover = GetParam();
  const bool gpu = handover != "host";
  ASSERT_NO_FATAL_FAILURE(create_instance());
  ASSERT_NO_FATAL_FAILURE(run_to_focused());
  const XrSpace local = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  XrViewConfigurationView vcv[2] = {{XR_TYPE_VIEW_CONFIGURATION_VIEW}, {XR_TYPE_VIEW_CONFIGURATION_VIEW}};
  uint32_t n = 0;
  ASSERT_EQ(xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 2, &n, vcv),
            XR_SUCCESS);
  const auto w = int32_t(vcv[0].recommendedImageRectWidth), h = int32_t(vcv[0].recommendedImageRectHeight);
  for (XrSwapchain& sc : eye_) sc = color_swapchain(uint32_t(w), uint32_t(h));
  // The application's threads, its Vulkan device's among them, before the render thread exists.
  const std::map<int, ThreadInfo> app_threads = threads();

  // Until the records show three distinct traced frames (the first is the renderer's set-up):
  // the waiter runs one frame ahead of the submitting thread.
  constexpr int kMaxFrames = 20000;  // a hang guard only: far more than three renders take
  std::mutex m;
  std::condition_variable cv;
  std::deque<XrTime> ready;
  bool stop = false, waiter_done = false;  // under m
  std::atomic<int> failures{0};
  std::thread waiter([&] {
    for (int i = 0; i < kMaxFrames; ++i) {
      {
        std::unique_lock lock(m);
        cv.wait(lock, [&] { return ready.size() < 2 || stop; });
        if (stop) break;
      }
      XrFrameState fs{XR_TYPE_FRAME_STATE};
      if (xrWaitFrame(session_, nullptr, &fs) != XR_SUCCESS) ++failures;
      std::lock_guard lock(m);
      ready.push_back(fs.predictedDisplayTime);
      cv.notify_all();
    }
    std::lock_guard lock(m);
    waiter_done = true;
    cv.notify_all();
  });
  // The next waited frame; 0 once the waiter has stopped and every waited frame was taken.
  const auto next_waited = [&] {
    std::unique_lock lock(m);
    cv.wait(lock, [&] { return !ready.empty() || waiter_done; });
    if (ready.empty()) return XrTime(0);
    const XrTime t = ready.front();
    ready.pop_front();
    cv.notify_all();
    return t;
  };
  const auto submit = [&](XrTime t) {
    if (xrBeginFrame(session_, nullptr) != XR_SUCCESS) ++failures;
    XrViewLocateInfo li{XR_TYPE_VIEW_LOCATE_INFO};
    li.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    li.displayTime = t;
    li.space = local;
    XrViewState vs{XR_TYPE_VIEW_STATE};
    XrView located[2] = {{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
    ASSERT_EQ(xrLocateViews(session_, &li, &vs, 2, &n, located), XR_SUCCESS);
    XrCompositionLayerProjectionView views[2];
    for (int e = 0; e < 2; ++e) {
      ASSERT_NO_FATAL_FAILURE(cycle(eye_[e]));
      views[e] = {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW};
      views[e].pose = located[e].pose;
      views[e].fov = located[e].fov;
      views[e].subImage = {eye_[e], {{0, 0}, {w, h}}, 0};
    }
    XrCompositionLayerProjection proj{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
    proj.space = local;
    proj.viewCount = 2;
    proj.views = views;
    const XrCompositionLayerBaseHeader* layers[] = {reinterpret_cast<const XrCompositionLayerBaseHeader*>(&proj)};
    XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
    ei.displayTime = t;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    ei.layerCount = 1;
    ei.layers = layers;
    if (xrEndFrame(session_, &ei) != XR_SUCCESS) ++failures;
  };
  int ended = 0;
  std::set<std::int64_t> traced;
  while (ended < kMaxFrames) {
    const XrTime t = next_waited();
    if (t == 0) break;
    ASSERT_NO_FATAL_FAILURE(submit(t));
    ++ended;
    if (ended % 8 == 0) {
      traced.clear();
      for (const auto& r : records(timing()))
        if (r["traced_frame"].get<std::int64_t>() >= 0) traced.insert(r["traced_frame"].get<std::int64_t>());
      if (traced.size() >= 3) break;
    }
  }
  {
    std::lock_guard lock(m);
    stop = true;
  }
  cv.notify_all();
  // The waiter may be inside xrWaitFrame until the frame it waits behind begins: the frames it
  // got are still submitted.
  for (XrTime t = next_waited(); t != 0; t = next_waited()) {
    ASSERT_NO_FATAL_FAILURE(submit(t));
    ++ended;
  }
  waiter.join();
  EXPECT_EQ(failures, 0);
  ASSERT_GE(traced.size(), 3u) << "the render thread finished fewer than three frames in " << ended << " frames";

  const std::string log = read_text(out_->path() + "/layer.log");
  EXPECT_NE(log.find("render async"), std::string::npos) << log;
  EXPECT_NE(log.find(gpu ? "composition: on the GPU" : "composition: on the host (configured)"), std::string::npos)
      << log;
  EXPECT_EQ(log.find("internal failure"), std::string::npos) << log;
  if (gpu) {
    const char* expected = handover == "application-device"
                               ? "hand-over: the application's device (the path tracer runs on it, on its own queue "
                                 "(family 0, index 1)"
                           : handover == "shared-memory" ? "hand-over: shared memory"
                                                         : "hand-over: through the host";
    EXPECT_NE(log.find(expected), std::string::npos) << log;
    if (handover == "host-slot") {  // and why: the configuration asked for it
      EXPECT_NE(log.find("configured (\"handover\": \"host\")"), std::string::npos) << log;
    }
  }

  // CPU priority: the render thread and the threads of the device it created (lavapipe's
  // rasteriser threads, "llvmpipe-N", and its compute workers, which inherit the name
  // "fovea-render") run at nice 19; the application's threads, its device's included, keep
  // theirs (Mesa's disk-cache threads lower themselves to SCHED_IDLE whoever creates them).
  const auto lowered = [](const ThreadInfo& t) { return t.policy == SCHED_OTHER && t.nice == 19; };
  const std::map<int, ThreadInfo> now = threads();
  const ThreadInfo me = now.at(int(syscall(SYS_gettid)));
  EXPECT_EQ(me.policy, SCHED_OTHER);
  EXPECT_EQ(me.nice, app_threads.at(int(syscall(SYS_gettid))).nice);
  int render = 0, render_device = 0, app_device = 0;
  int log_writer = 0;
  for (const auto& [tid, t] : now) {
    const bool rasteriser = t.name.rfind("llvmpipe-", 0) == 0;
    // The layer's timing-log writer, started with the session (before the snapshot above):
    // it lowers itself to nice 19.
    if (t.name == "fovea-log") {
      ++log_writer;
      EXPECT_TRUE(lowered(t)) << "the timing-log thread " << tid << " nice " << t.nice;
      continue;
    }
    if (app_threads.count(tid)) {
      if (t.name.find("disk$") == std::string::npos) {
        EXPECT_EQ(t.policy, app_threads.at(tid).policy) << t.name << " " << tid;
        EXPECT_EQ(t.nice, app_threads.at(tid).nice) << t.name << " " << tid;
      }
      app_device += rasteriser;
      continue;
    }
    if (t.name == "fovea-render") {
      ++render;
      EXPECT_TRUE(lowered(t)) << "the render thread or a device thread it created: " << tid << " nice " << t.nice;
    }
    if (rasteriser) {
      ++render_device;
      EXPECT_TRUE(lowered(t)) << "the render device's " << t.name << " " << tid << " nice " << t.nice;
    }
  }
  EXPECT_GE(render, 1);
  EXPECT_EQ(log_writer, 1);
  if (app_device > 0 && handover == "application-device") {
    EXPECT_EQ(render_device, 0) << "the path tracer made no device of its own";
  } else if (app_device > 0) {  // lavapipe: as many rasteriser threads per device, compute workers too
    EXPECT_EQ(render_device, app_device) << "one device's rasteriser threads each";
    EXPECT_GT(render, 1) << "the render device's compute workers";
  }

  // Teardown while the render thread is inside a render's delay: it is woken and joined.
  for (XrSwapchain& sc : eye_) {
    EXPECT_EQ(xrDestroySwapchain(sc), XR_SUCCESS);
    sc = XR_NULL_HANDLE;
  }
  EXPECT_EQ(xrDestroySession(session_), XR_SUCCESS);
  session_ = XR_NULL_HANDLE;

  // The timing log is complete once the session is gone (its writer thread writes what it
  // still holds; while the session runs the file lags the frames by up to a flush period).
  const auto recs = records(timing());
  ASSERT_GE(recs.size(), std::size_t(ended - 1));
  // Every application frame was ended and logged, far more of them than frames traced: while
  // the render thread sleeps 700 ms per frame, xrEndFrame returns with the newest finished one.
  EXPECT_GT(recs.size(), 4 * traced.size()) << recs.size() << " frames, " << traced.size() << " traced";
  std::int64_t last_traced = -1, last_display = 0;
  int replaced = 0;
  std::map<std::int64_t, std::int64_t> display_of;  // the application's frame index -> its display time
  for (const auto& r : recs) display_of[r["frame"].get<std::int64_t>()] = r["predicted_display_ns"].get<std::int64_t>();
  for (const auto& r : recs) {
    // One clock: the runtime's XrTime values converted with XR_KHR_convert_timespec_time.
    EXPECT_TRUE(r["xr_time_converted"].get<bool>()) << r.dump();
    const std::int64_t tf = r["traced_frame"].get<std::int64_t>();
    const std::int64_t display = r["predicted_display_ns"].get<std::int64_t>();
    EXPECT_GT(display, last_display) << r.dump();  // the queue matched each end to its own wait
    last_display = display;
    EXPECT_EQ(r["replaced"].get<bool>(), tf >= 0) << r.dump();
    if (tf < 0) {
      EXPECT_EQ(last_traced, -1) << "a frame after the first traced one was not replaced: " << r.dump();
      continue;
    }
    ++replaced;
    // The newest finished frame: never an older one than the previous frame showed.
    EXPECT_GE(tf, last_traced) << r.dump();
    last_traced = tf;
    // Traced for views submitted earlier (or these): its age is never negative, its gaze sample named.
    EXPECT_LE(r["traced_for_ns"].get<std::int64_t>(), display) << r.dump();
    // The application's frame whose views it was traced for (traced_frame counts render
    // requests, which skip the frames the render thread never picked up): an earlier frame
    // of the log, or this one, with that display time.
    const std::int64_t for_frame = r["traced_for_frame"].get<std::int64_t>();
    EXPECT_LE(for_frame, r["frame"].get<std::int64_t>()) << r.dump();
    if (display_of.count(for_frame)) {
      EXPECT_EQ(display_of[for_frame], r["traced_for_ns"].get<std::int64_t>()) << r.dump();
    }
    EXPECT_GE(r["traced_age_ns"].get<std::int64_t>(), 0) << r.dump();
    EXPECT_GT(r["traced_done_ns"].get<std::int64_t>(), 0) << r.dump();
    EXPECT_GT(r["gaze_read_ns"].get<std::int64_t>(), 0) << r.dump();
    EXPECT_GT(r["render_ms"].get<double>(), 0) << r.dump();
    // Composited on the application's device without a host copy of its images, or on the
    // host with one read-back (both views) per frame.
    EXPECT_EQ(r["composited_on_gpu"].get<bool>(), gpu) << r.dump();
    EXPECT_EQ(r["host_readbacks"].get<std::int64_t>(), gpu ? 0 : 1) << r.dump();
    // How the traced frame got there, and the bytes it moved through the host: none when the
    // layer's device wrote it into the application's device memory (docs/openxr.md).
    EXPECT_EQ(r["handover"], handover) << r.dump();
    if (handover == "shared-memory" || handover == "application-device") {
      EXPECT_EQ(r["host_bytes"].get<std::int64_t>(), 0) << r.dump();
    } else {
      // Per eye the linear colour read back (RGBA32F) and written encoded (RGBA8), and no
      // depth: this application submits none, so the layer neither traces nor moves it.
      EXPECT_EQ(r["host_bytes"].get<std::int64_t>(), std::int64_t(2) * w * h * (16 + 4)) << r.dump();
    }
    if (gpu) {
      // The render thread wrote the traced frame into a slot of the application's device
      // memory (no frame copied on this thread); the composition's command buffers were
      // recorded once per combination of images (three images per swapchain, acquired in
      // turn; a second copy while one is in flight), at most the 8 kept, and its descriptor
      // set written once, not per frame.
      EXPECT_GE(r["traced_slot"].get<std::int64_t>(), 0) << r.dump();
      EXPECT_LE(r["recordings"].get<std::int64_t>(), 8) << r.dump();
      EXPECT_EQ(r["descriptor_updates"].get<std::int64_t>(), 1) << r.dump();
    } else {
      EXPECT_EQ(r["traced_slot"].get<std::int64_t>(), -1) << r.dump();
    }
  }
  EXPECT_GT(replaced, 0);
}

INSTANTIATE_TEST_SUITE_P(Handover, AsyncLayer,
                         ::testing::Values("application-device", "shared-memory", "host-slot", "host"),
                         [](const ::testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           for (char& c : name) c = c == '-' ? '_' : c;
                           return name;
                         });

}  // namespace
}  // namespace fovea::test
