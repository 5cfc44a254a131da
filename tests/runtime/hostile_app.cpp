#include "hostile_app.hpp"

#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

namespace fovea::test {

namespace {

const XrCompositionLayerBaseHeader* base(const void* p) { return static_cast<const XrCompositionLayerBaseHeader*>(p); }

// An opaque frame end info for display time t with the one layer *layer.
XrFrameEndInfo end_info(XrTime t, const XrCompositionLayerBaseHeader* const* layer) {
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = t;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  ei.layerCount = 1;
  ei.layers = layer;
  return ei;
}

template <class Handle>
Handle garbage() {
  return reinterpret_cast<Handle>(std::uint64_t(0x5eed'0bad'f00d));
}

constexpr const char* kLayerVariables[] = {"XR_API_LAYER_PATH", "XR_ENABLE_API_LAYERS", "FOVEA_LAYER_OUT",
                                           "FOVEA_LAYER_LOG_FILE", "FOVEA_SCENE", "FOVEA_LAYER_SCENE",
                                           "XDG_CONFIG_HOME", "FOVEA_RUNTIME_OUT", "FOVEA_RUNTIME_PNG_EVERY"};

}  // namespace

void HostileApp::SetUp() {
  XrTest::SetUp();  // the tiny display preset
  out_ = std::make_unique<TempDir>("hostile");
  // The runtime's compositor reads the submitted images back every other frame.
  setenv("FOVEA_RUNTIME_OUT", out_->path().c_str(), 1);
  setenv("FOVEA_RUNTIME_PNG_EVERY", "2", 1);
  unsetenv("FOVEA_SCENE");
  unsetenv("FOVEA_LAYER_SCENE");
  setenv("XDG_CONFIG_HOME", (out_->path() + "/no-config").c_str(), 1);  // no user layer.json
  const HostileVariant& v = GetParam();
  if (!v.layer_dir.empty()) {
    setenv("XR_API_LAYER_PATH", v.layer_dir.c_str(), 1);
    setenv("XR_ENABLE_API_LAYERS", "XR_APILAYER_FOVEA_path_tracing", 1);
    setenv("FOVEA_LAYER_OUT", out_->path().c_str(), 1);
    setenv("FOVEA_LAYER_LOG_FILE", (out_->path() + "/layer.log").c_str(), 1);
    if (!v.scene.empty()) setenv("FOVEA_SCENE", v.scene.c_str(), 1);
  }
}

void HostileApp::TearDown() {
  XrTest::TearDown();
  for (const char* k : kLayerVariables) unsetenv(k);
}

void HostileApp::expect(const char* what, XrResult got, XrResult expected) {
  char g[XR_MAX_RESULT_STRING_SIZE] = "?", e[XR_MAX_RESULT_STRING_SIZE] = "?";
  if (instance_) {
    xrResultToString(instance_, got, g);
    xrResultToString(instance_, expected, e);
  }
  EXPECT_EQ(got, expected) << what << ": got " << g << ", expected " << e;
  std::printf("[hostile] %-58s %s\n", what, g);
}

void HostileApp::start() {
  create_instance();
  run_to_focused();
  local_ = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  XrViewConfigurationView vcv[2] = {{XR_TYPE_VIEW_CONFIGURATION_VIEW}, {XR_TYPE_VIEW_CONFIGURATION_VIEW}};
  uint32_t n = 0;
  ASSERT_EQ(xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 2, &n, vcv),
            XR_SUCCESS);
  width_ = vcv[0].recommendedImageRectWidth;
  height_ = vcv[0].recommendedImageRectHeight;
  for (XrSwapchain& sc : eye_) {
    sc = color_swapchain(width_, height_);
    cycle(sc);
  }
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  ASSERT_EQ(frame({}, &fs), XR_SUCCESS);
  XrViewLocateInfo li{XR_TYPE_VIEW_LOCATE_INFO};
  li.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  li.displayTime = fs.predictedDisplayTime;
  li.space = local_;
  XrViewState vs{XR_TYPE_VIEW_STATE};
  located_[0] = located_[1] = {XR_TYPE_VIEW};
  ASSERT_EQ(xrLocateViews(session_, &li, &vs, 2, &n, located_), XR_SUCCESS);
}

XrTime HostileApp::open_frame() {
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  EXPECT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
  const XrResult r = xrBeginFrame(session_, nullptr);
  EXPECT_TRUE(r == XR_SUCCESS || r == XR_FRAME_DISCARDED) << r;
  return fs.predictedDisplayTime;
}

void HostileApp::cycle(XrSwapchain sc) {
  uint32_t index = 0;
  ASSERT_EQ(xrAcquireSwapchainImage(sc, nullptr, &index), XR_SUCCESS);
  XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
  wi.timeout = XR_INFINITE_DURATION;
  ASSERT_EQ(xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
  ASSERT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
}

const XrCompositionLayerBaseHeader* HostileApp::projection() {
  for (int i = 0; i < 3; ++i) {
    views_[i] = {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW};
    views_[i].pose = located_[i % 2].pose;
    views_[i].fov = located_[i % 2].fov;
    views_[i].subImage.swapchain = eye_[i % 2];
    views_[i].subImage.imageRect = {{0, 0}, {int32_t(width_), int32_t(height_)}};
  }
  projection_ = {XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  projection_.space = local_;
  projection_.viewCount = 2;
  projection_.views = views_;
  return base(&projection_);
}

void HostileApp::expect_end(const char* what, XrResult expected, const std::function<void(XrFrameEndInfo&)>& spoil) {
  const XrTime t = open_frame();
  for (XrSwapchain sc : eye_) cycle(sc);
  const XrCompositionLayerBaseHeader* layers[] = {projection()};
  XrFrameEndInfo ei = end_info(t, layers);
  spoil(ei);
  expect(what, xrEndFrame(session_, &ei), expected);
}

void HostileApp::normal_frames(int n) {
  for (int i = 0; i < n; ++i) expect_end("normal frame after the hostile calls", XR_SUCCESS, [](XrFrameEndInfo&) {});
}

void HostileApp::check_layer_after() {
  if (GetParam().layer_dir.empty()) return;
  const std::string log = read_text(out_->path() + "/layer.log");
  EXPECT_EQ(log.find("internal failure"), std::string::npos) << log;
  EXPECT_EQ(log.find("passes this session through"), std::string::npos) << log;
  const auto last_record = [&] {
    std::ifstream in(out_->path() + "/layer_timing.jsonl");
    std::string line, last;
    while (std::getline(in, line)) last = line;
    return last;
  };
  const bool rendering = !GetParam().scene.empty();
  // The render thread's first traced frame comes when it is done (async): on a loaded machine
  // later than the hostile calls' frames end. Normal frames for it, up to about 10 s.
  std::string last = last_record();
  for (int i = 0; rendering && last.find("\"replaced\":true") == std::string::npos && i < 700; ++i) {
    normal_frames(1);
    last = last_record();
  }
  EXPECT_NE(last.find(rendering ? "\"replaced\":true" : "\"replaced\":false"), std::string::npos) << last;
}

// Bad composition layers and frame end infos: each is refused with its code and the frame
// stays open (the next xrBeginFrame discards it); afterwards normal frames succeed.
TEST_P(HostileApp, BadLayersAreRefusedWithTheirCodes) {
  ASSERT_NO_FATAL_FAILURE(start());
  auto& P = projection_;
  auto& V = views_;

  // A projection layer whose swapchain was destroyed after its image was released.
  XrSwapchain gone = color_swapchain(width_, height_);
  cycle(gone);
  ASSERT_EQ(xrDestroySwapchain(gone), XR_SUCCESS);
  expect_end("projection view on a destroyed swapchain", XR_ERROR_HANDLE_INVALID,
             [&](XrFrameEndInfo&) { V[1].subImage.swapchain = gone; });
  expect_end("projection view on a garbage swapchain handle", XR_ERROR_HANDLE_INVALID,
             [&](XrFrameEndInfo&) { V[0].subImage.swapchain = garbage<XrSwapchain>(); });
  // A swapchain that never released an image has nothing to show.
  XrSwapchain fresh = color_swapchain(width_, height_);
  expect_end("projection view on a never released swapchain", XR_ERROR_LAYER_INVALID,
             [&](XrFrameEndInfo&) { V[0].subImage.swapchain = fresh; });
  ASSERT_EQ(xrDestroySwapchain(fresh), XR_SUCCESS);
  XrSpace space = reference_space(XR_REFERENCE_SPACE_TYPE_VIEW);
  ASSERT_EQ(xrDestroySpace(space), XR_SUCCESS);
  expect_end("projection layer in a destroyed space", XR_ERROR_HANDLE_INVALID, [&](XrFrameEndInfo&) { P.space = space; });

  expect_end("projection layer with 1 view", XR_ERROR_VALIDATION_FAILURE, [&](XrFrameEndInfo&) { P.viewCount = 1; });
  expect_end("projection layer with 3 views", XR_ERROR_VALIDATION_FAILURE, [&](XrFrameEndInfo&) { P.viewCount = 3; });
  expect_end("projection layer with 2 views and a NULL array", XR_ERROR_VALIDATION_FAILURE,
             [&](XrFrameEndInfo&) { P.views = nullptr; });
  expect_end("projection view of the wrong structure type", XR_ERROR_VALIDATION_FAILURE,
             [&](XrFrameEndInfo&) { V[1].type = XR_TYPE_VIEW; });
  expect_end("projection view with a zero-width imageRect", XR_ERROR_SWAPCHAIN_RECT_INVALID,
             [&](XrFrameEndInfo&) { V[0].subImage.imageRect.extent.width = 0; });
  expect_end("projection view with a negative-height imageRect", XR_ERROR_SWAPCHAIN_RECT_INVALID,
             [&](XrFrameEndInfo&) { V[1].subImage.imageRect.extent.height = -16; });
  expect_end("projection view with a negative imageRect offset", XR_ERROR_SWAPCHAIN_RECT_INVALID,
             [&](XrFrameEndInfo&) { V[0].subImage.imageRect.offset.x = -1; });
  expect_end("projection view with an imageRect past the image", XR_ERROR_SWAPCHAIN_RECT_INVALID,
             [&](XrFrameEndInfo&) { V[1].subImage.imageRect.offset.y = 1; });
  expect_end("projection view with imageArrayIndex out of range", XR_ERROR_VALIDATION_FAILURE,
             [&](XrFrameEndInfo&) { V[0].subImage.imageArrayIndex = 1; });

  // The layer list itself.
  XrCompositionLayerBaseHeader unknown{XR_TYPE_UNKNOWN};
  const XrCompositionLayerBaseHeader* with_unknown[] = {base(&P), &unknown};
  expect_end("layer of unknown type (XR_TYPE_UNKNOWN)", XR_ERROR_LAYER_INVALID, [&](XrFrameEndInfo& e) {
    e.layerCount = 2;
    e.layers = with_unknown;
  });
  XrSwapchainCreateInfo not_a_layer{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  const XrCompositionLayerBaseHeader* with_wrong[] = {base(&not_a_layer), base(&P)};
  expect_end("layer of a structure type that is not a layer", XR_ERROR_LAYER_INVALID, [&](XrFrameEndInfo& e) {
    e.layerCount = 2;
    e.layers = with_wrong;
  });
  const XrCompositionLayerBaseHeader* with_null[] = {base(&P), nullptr};
  expect_end("NULL pointer in the layer list", XR_ERROR_LAYER_INVALID, [&](XrFrameEndInfo& e) {
    e.layerCount = 2;
    e.layers = with_null;
  });
  expect_end("layerCount 1 with a NULL layer array", XR_ERROR_VALIDATION_FAILURE,
             [&](XrFrameEndInfo& e) { e.layers = nullptr; });
  std::vector<const XrCompositionLayerBaseHeader*> many(64, base(&P));
  expect_end("64 layers (above the runtime's limit)", XR_ERROR_LAYER_LIMIT_EXCEEDED, [&](XrFrameEndInfo& e) {
    e.layerCount = uint32_t(many.size());
    e.layers = many.data();
  });

  // The frame end info.
  expect_end("environmentBlendMode ADDITIVE (unsupported)", XR_ERROR_ENVIRONMENT_BLEND_MODE_UNSUPPORTED,
             [&](XrFrameEndInfo& e) { e.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_ADDITIVE; });
  expect_end("environmentBlendMode not an enum value", XR_ERROR_VALIDATION_FAILURE,
             [&](XrFrameEndInfo& e) { e.environmentBlendMode = XrEnvironmentBlendMode(0x7777); });
  expect_end("displayTime 0", XR_ERROR_TIME_INVALID, [&](XrFrameEndInfo& e) { e.displayTime = 0; });
  expect_end("displayTime negative", XR_ERROR_TIME_INVALID, [&](XrFrameEndInfo& e) { e.displayTime = -1000; });
  expect_end("frame end info of the wrong structure type", XR_ERROR_VALIDATION_FAILURE,
             [&](XrFrameEndInfo& e) { e.type = XR_TYPE_FRAME_BEGIN_INFO; });
  open_frame();
  expect("xrEndFrame with a NULL frame end info", xrEndFrame(session_, nullptr), XR_ERROR_VALIDATION_FAILURE);

  normal_frames(3);
  check_layer_after();
}

// Swapchains misused: acquire/wait/release out of order, destroyed mid-frame (between
// acquire and release, and between release and xrEndFrame), used after destruction.
TEST_P(HostileApp, SwapchainMisuseIsRefusedWithTheirCodes) {
  ASSERT_NO_FATAL_FAILURE(start());
  XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
  wi.timeout = XR_INFINITE_DURATION;
  uint32_t index = 0;
  XrSwapchain sc = color_swapchain(width_, height_);
  expect("release without acquire", xrReleaseSwapchainImage(sc, nullptr), XR_ERROR_CALL_ORDER_INVALID);
  expect("wait without acquire", xrWaitSwapchainImage(sc, &wi), XR_ERROR_CALL_ORDER_INVALID);
  expect("acquire 1 of 3", xrAcquireSwapchainImage(sc, nullptr, &index), XR_SUCCESS);
  expect("release acquired but not waited", xrReleaseSwapchainImage(sc, nullptr), XR_ERROR_CALL_ORDER_INVALID);
  expect("acquire 2 of 3 (without wait/release)", xrAcquireSwapchainImage(sc, nullptr, &index), XR_SUCCESS);
  expect("acquire 3 of 3 (without wait/release)", xrAcquireSwapchainImage(sc, nullptr, &index), XR_SUCCESS);
  expect("acquire a 4th image of 3", xrAcquireSwapchainImage(sc, nullptr, &index), XR_ERROR_CALL_ORDER_INVALID);
  expect("acquire with a NULL index", xrAcquireSwapchainImage(sc, nullptr, nullptr), XR_ERROR_VALIDATION_FAILURE);
  XrSwapchainImageAcquireInfo wrong_acquire{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
  expect("acquire info of the wrong structure type", xrAcquireSwapchainImage(sc, &wrong_acquire, &index),
         XR_ERROR_VALIDATION_FAILURE);
  expect("wait for acquired image 1", xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
  // The CTS's pattern: a waited image must be released before the next wait.
  expect("wait for image 2 before releasing image 1", xrWaitSwapchainImage(sc, &wi), XR_ERROR_CALL_ORDER_INVALID);
  expect("release image 1", xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
  expect("wait for acquired image 2", xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
  expect("release image 2", xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
  expect("release image 3 (acquired, never waited)", xrReleaseSwapchainImage(sc, nullptr), XR_ERROR_CALL_ORDER_INVALID);
  expect("wait with a NULL wait info", xrWaitSwapchainImage(sc, nullptr), XR_ERROR_VALIDATION_FAILURE);

  // Destroyed with an image acquired and waited on, before its release.
  expect("destroy with an image acquired", xrDestroySwapchain(sc), XR_SUCCESS);
  expect("release on the destroyed swapchain", xrReleaseSwapchainImage(sc, nullptr), XR_ERROR_HANDLE_INVALID);
  expect("acquire on the destroyed swapchain", xrAcquireSwapchainImage(sc, nullptr, &index), XR_ERROR_HANDLE_INVALID);
  expect("destroy the destroyed swapchain", xrDestroySwapchain(sc), XR_ERROR_HANDLE_INVALID);
  uint32_t count = 0;
  expect("enumerate images of the destroyed swapchain", xrEnumerateSwapchainImages(sc, 0, &count, nullptr),
         XR_ERROR_HANDLE_INVALID);
  expect("acquire on a garbage swapchain handle", xrAcquireSwapchainImage(garbage<XrSwapchain>(), nullptr, &index),
         XR_ERROR_HANDLE_INVALID);

  // A static swapchain hands out its one image once.
  XrSwapchainCreateInfo ci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  ci.createFlags = XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT;
  ci.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT;
  ci.format = VK_FORMAT_R8G8B8A8_SRGB;
  ci.sampleCount = ci.faceCount = ci.arraySize = ci.mipCount = 1;
  ci.width = width_;
  ci.height = height_;
  XrSwapchain still = XR_NULL_HANDLE;
  ASSERT_EQ(xrCreateSwapchain(session_, &ci, &still), XR_SUCCESS);
  cycle(still);
  expect("acquire a static swapchain twice", xrAcquireSwapchainImage(still, nullptr, &index), XR_ERROR_CALL_ORDER_INVALID);
  ASSERT_EQ(xrDestroySwapchain(still), XR_SUCCESS);

  // An eye swapchain destroyed inside the frame between its acquire and its release, then
  // submitted anyway.
  const XrTime t = open_frame();
  cycle(eye_[0]);
  ASSERT_EQ(xrAcquireSwapchainImage(eye_[1], nullptr, &index), XR_SUCCESS);
  ASSERT_EQ(xrWaitSwapchainImage(eye_[1], &wi), XR_SUCCESS);
  const XrSwapchain destroyed = eye_[1];
  expect("destroy an eye swapchain between acquire and release", xrDestroySwapchain(destroyed), XR_SUCCESS);
  expect("release the destroyed eye swapchain", xrReleaseSwapchainImage(destroyed, nullptr), XR_ERROR_HANDLE_INVALID);
  const XrCompositionLayerBaseHeader* layers[] = {projection()};
  XrFrameEndInfo ei = end_info(t, layers);
  expect("xrEndFrame on the eye swapchain destroyed before release", xrEndFrame(session_, &ei), XR_ERROR_HANDLE_INVALID);
  eye_[1] = color_swapchain(width_, height_);
  cycle(eye_[1]);

  // Destroyed between its release and xrEndFrame.
  expect_end("eye swapchain destroyed between release and xrEndFrame", XR_ERROR_HANDLE_INVALID, [&](XrFrameEndInfo&) {
    XrSwapchain old = eye_[0];
    ASSERT_EQ(xrDestroySwapchain(old), XR_SUCCESS);
    eye_[0] = color_swapchain(width_, height_);
    views_[0].subImage.swapchain = old;
  });
  cycle(eye_[0]);
  normal_frames(3);
  check_layer_after();
}

// Frame functions out of order, invalid and destroyed session and space handles, the
// frame loop after xrEndSession; the session still runs normally in between and ends
// through the state machine.
TEST_P(HostileApp, OutOfOrderCallsAndDeadHandlesAreRefused) {
  ASSERT_NO_FATAL_FAILURE(start());
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  const XrCompositionLayerBaseHeader* layers[] = {projection()};
  ei.layerCount = 1;
  ei.layers = layers;

  ei.displayTime = 1'000'000;  // any valid time: the call order is checked first
  expect("xrEndFrame without xrWaitFrame/xrBeginFrame", xrEndFrame(session_, &ei), XR_ERROR_CALL_ORDER_INVALID);
  expect("xrBeginFrame without xrWaitFrame", xrBeginFrame(session_, nullptr), XR_ERROR_CALL_ORDER_INVALID);
  expect("xrWaitFrame", xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
  ei.displayTime = fs.predictedDisplayTime;
  expect("xrEndFrame after xrWaitFrame without xrBeginFrame", xrEndFrame(session_, &ei), XR_ERROR_CALL_ORDER_INVALID);
  expect("xrBeginFrame", xrBeginFrame(session_, nullptr), XR_SUCCESS);
  expect("xrBeginFrame twice", xrBeginFrame(session_, nullptr), XR_ERROR_CALL_ORDER_INVALID);
  for (XrSwapchain sc : eye_) cycle(sc);
  expect("xrEndFrame", xrEndFrame(session_, &ei), XR_SUCCESS);
  expect("xrEndFrame twice", xrEndFrame(session_, &ei), XR_ERROR_CALL_ORDER_INVALID);
  // A second xrWaitFrame while a frame is begun: its xrBeginFrame discards the open frame.
  expect("xrWaitFrame", xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
  expect("xrBeginFrame", xrBeginFrame(session_, nullptr), XR_SUCCESS);
  expect("xrWaitFrame with a frame begun", xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
  expect("xrBeginFrame discarding the open frame", xrBeginFrame(session_, nullptr), XR_FRAME_DISCARDED);
  ei.displayTime = fs.predictedDisplayTime;
  for (XrSwapchain sc : eye_) cycle(sc);
  expect("xrEndFrame", xrEndFrame(session_, &ei), XR_SUCCESS);
  XrFrameWaitInfo wrong_wait{XR_TYPE_FRAME_BEGIN_INFO};
  expect("xrWaitFrame with a wait info of the wrong type", xrWaitFrame(session_, &wrong_wait, &fs),
         XR_ERROR_VALIDATION_FAILURE);
  expect("xrWaitFrame with a NULL frame state", xrWaitFrame(session_, nullptr, nullptr), XR_ERROR_VALIDATION_FAILURE);
  XrFrameState wrong_state{XR_TYPE_VIEW_STATE};
  expect("xrWaitFrame with a frame state of the wrong type", xrWaitFrame(session_, nullptr, &wrong_state),
         XR_ERROR_VALIDATION_FAILURE);

  // Invalid and destroyed handles.
  expect("xrWaitFrame on a garbage session", xrWaitFrame(garbage<XrSession>(), nullptr, &fs), XR_ERROR_HANDLE_INVALID);
  expect("xrBeginFrame on a garbage session", xrBeginFrame(garbage<XrSession>(), nullptr), XR_ERROR_HANDLE_INVALID);
  expect("xrEndFrame on a garbage session", xrEndFrame(garbage<XrSession>(), &ei), XR_ERROR_HANDLE_INVALID);
  expect("xrWaitFrame on XR_NULL_HANDLE", xrWaitFrame(XR_NULL_HANDLE, nullptr, &fs), XR_ERROR_HANDLE_INVALID);
  XrSpace view = reference_space(XR_REFERENCE_SPACE_TYPE_VIEW);
  XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
  expect("xrLocateSpace", xrLocateSpace(view, local_, fs.predictedDisplayTime, &loc), XR_SUCCESS);
  expect("xrDestroySpace", xrDestroySpace(view), XR_SUCCESS);
  expect("xrLocateSpace of a destroyed space", xrLocateSpace(view, local_, fs.predictedDisplayTime, &loc),
         XR_ERROR_HANDLE_INVALID);
  expect("xrLocateSpace relative to a garbage space",
         xrLocateSpace(local_, garbage<XrSpace>(), fs.predictedDisplayTime, &loc), XR_ERROR_HANDLE_INVALID);
  expect("xrDestroySpace of a destroyed space", xrDestroySpace(view), XR_ERROR_HANDLE_INVALID);
  expect("xrLocateSpace at time 0", xrLocateSpace(local_, local_, 0, &loc), XR_ERROR_TIME_INVALID);

  normal_frames(3);
  check_layer_after();

  // Ending the session: too early, then through the state machine; the frame loop after it.
  expect("xrEndSession while running", xrEndSession(session_), XR_ERROR_SESSION_NOT_STOPPING);
  expect("xrRequestExitSession", xrRequestExitSession(session_), XR_SUCCESS);
  const auto states = poll_states();
  ASSERT_FALSE(states.empty());
  EXPECT_EQ(states.back(), XR_SESSION_STATE_STOPPING);
  expect("xrEndSession when stopping", xrEndSession(session_), XR_SUCCESS);
  expect("xrWaitFrame after xrEndSession", xrWaitFrame(session_, nullptr, &fs), XR_ERROR_SESSION_NOT_RUNNING);
  expect("xrBeginFrame after xrEndSession", xrBeginFrame(session_, nullptr), XR_ERROR_SESSION_NOT_RUNNING);
  expect("xrEndFrame after xrEndSession", xrEndFrame(session_, &ei), XR_ERROR_SESSION_NOT_RUNNING);
  expect("xrEndSession twice", xrEndSession(session_), XR_ERROR_SESSION_NOT_RUNNING);
  EXPECT_EQ(poll_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_EXITING}));

  // The session destroyed: its handle and its children's are dead.
  const XrSession dead = session_;
  expect("xrDestroySession", xrDestroySession(dead), XR_SUCCESS);
  session_ = XR_NULL_HANDLE;
  expect("xrWaitFrame on a destroyed session", xrWaitFrame(dead, nullptr, &fs), XR_ERROR_HANDLE_INVALID);
  expect("xrEndFrame on a destroyed session", xrEndFrame(dead, &ei), XR_ERROR_HANDLE_INVALID);
  expect("xrDestroySession twice", xrDestroySession(dead), XR_ERROR_HANDLE_INVALID);
  uint32_t index = 0;
  expect("acquire on a swapchain of the destroyed session", xrAcquireSwapchainImage(eye_[0], nullptr, &index),
         XR_ERROR_HANDLE_INVALID);
  expect("xrLocateSpace of a space of the destroyed session", xrLocateSpace(local_, local_, 1, &loc),
         XR_ERROR_HANDLE_INVALID);
}

// A pipelined engine (the CTS's pipelined-submission pattern): xrWaitFrame on one thread,
// xrBeginFrame/xrEndFrame on another. Every call succeeds, no frame is discarded, display
// times increase, and a further xrWaitFrame returns only after the previous frame was begun.
TEST_P(HostileApp, PipelinedFramesOnTwoThreads) {
  ASSERT_NO_FATAL_FAILURE(start());
  constexpr int kFrames = 8;
  std::mutex m;
  std::condition_variable cv;
  std::deque<XrTime> ready;
  std::atomic<int> begun{0};
  std::vector<XrResult> wait_results, begin_results, end_results;
  std::vector<int> begun_at_wait;  // frames begun when each xrWaitFrame returned
  std::thread waiter([&] {
    for (int i = 0; i < kFrames; ++i) {
      XrFrameState fs{XR_TYPE_FRAME_STATE};
      const XrResult r = xrWaitFrame(session_, nullptr, &fs);
      std::lock_guard lock(m);
      wait_results.push_back(r);
      begun_at_wait.push_back(begun.load());
      ready.push_back(r == XR_SUCCESS ? fs.predictedDisplayTime : 0);
      cv.notify_all();
    }
  });
  XrTime last = 0;
  for (int i = 0; i < kFrames; ++i) {
    XrTime t = 0;
    {
      std::unique_lock lock(m);
      cv.wait(lock, [&] { return !ready.empty(); });
      t = ready.front();
      ready.pop_front();
    }
    ++begun;  // before the call: the waiter may return as soon as the runtime has begun it
    begin_results.push_back(xrBeginFrame(session_, nullptr));
    EXPECT_GT(t, last);
    last = t;
    for (XrSwapchain sc : eye_) cycle(sc);
    const XrCompositionLayerBaseHeader* layers[] = {projection()};
    const XrFrameEndInfo ei = end_info(t, layers);
    end_results.push_back(xrEndFrame(session_, &ei));
  }
  waiter.join();
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(wait_results[size_t(i)], XR_SUCCESS) << i;
    EXPECT_EQ(begin_results[size_t(i)], XR_SUCCESS) << i;
    EXPECT_EQ(end_results[size_t(i)], XR_SUCCESS) << i;
    EXPECT_GE(begun_at_wait[size_t(i)], i) << "xrWaitFrame " << i << " returned before frame " << i - 1 << " began";
  }
  check_layer_after();
}


}  // namespace fovea::test
