// The runtime through the real OpenXR loader: error codes of the specification for invalid
// handles, wrong structure types, calls in the wrong state and bad arguments; the session
// state machine; spaces, swapchains, frames, eye gaze and visibility masks.
#include <cmath>
#include <algorithm>
#include <cstring>
#include <limits>

#include <filesystem>
#include <fstream>

#include <glm/gtc/quaternion.hpp>

#include "fovea/xrcommon/timing_record.hpp"
#include "xr_fixture.hpp"
#include "xr_process.hpp"

namespace fovea::test {
namespace {

template <class H>
H bogus(std::uint64_t v) {
  return reinterpret_cast<H>(v);
}

// A stereo projection layer with both views on the whole of `sc` (64×72) in `space`.
struct StereoLayer {
  XrCompositionLayerProjectionView views[2];
  XrCompositionLayerProjection layer{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  StereoLayer(XrSwapchain sc, XrSpace space) {
    for (auto& v : views) {
      v = {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW};
      v.pose.orientation.w = 1;
      v.fov = {-0.8f, 0.8f, 0.8f, -0.8f};
      v.subImage.swapchain = sc;
      v.subImage.imageRect = {{0, 0}, {64, 72}};
    }
    layer.space = space;
    layer.viewCount = 2;
    layer.views = views;
  }
  StereoLayer(const StereoLayer&) = delete;  // `layer` points at `views`
  StereoLayer& operator=(const StereoLayer&) = delete;
  const XrCompositionLayerBaseHeader* header() const {
    return reinterpret_cast<const XrCompositionLayerBaseHeader*>(&layer);
  }
};

TEST_F(XrTest, InstanceBasics) {
  create_instance();
  XrInstanceProperties props{XR_TYPE_INSTANCE_PROPERTIES};
  ASSERT_EQ(xrGetInstanceProperties(instance_, &props), XR_SUCCESS);
  EXPECT_STREQ(props.runtimeName, "Fovea simulated HMD");
  XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES};
  ASSERT_EQ(xrGetSystemProperties(instance_, system_, &sp), XR_SUCCESS);
  EXPECT_TRUE(sp.trackingProperties.orientationTracking);
  char buf[XR_MAX_RESULT_STRING_SIZE];
  ASSERT_EQ(xrResultToString(instance_, XR_ERROR_SESSION_NOT_READY, buf), XR_SUCCESS);
  EXPECT_STREQ(buf, "XR_ERROR_SESSION_NOT_READY");
  char sbuf[XR_MAX_STRUCTURE_NAME_SIZE];
  ASSERT_EQ(xrStructureTypeToString(instance_, XR_TYPE_FRAME_STATE, sbuf), XR_SUCCESS);
  EXPECT_STREQ(sbuf, "XR_TYPE_FRAME_STATE");
}

TEST_F(XrTest, WrongStructureTypes) {
  create_instance();
  XrInstanceProperties props{XR_TYPE_SYSTEM_PROPERTIES};
  EXPECT_EQ(xrGetInstanceProperties(instance_, &props), XR_ERROR_VALIDATION_FAILURE);
  XrSystemGetInfo gi{XR_TYPE_SESSION_CREATE_INFO};
  gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  XrSystemId id = 0;
  EXPECT_EQ(xrGetSystem(instance_, &gi, &id), XR_ERROR_VALIDATION_FAILURE);
  XrSystemProperties sp{XR_TYPE_INSTANCE_PROPERTIES};
  EXPECT_EQ(xrGetSystemProperties(instance_, system_, &sp), XR_ERROR_VALIDATION_FAILURE);
  XrEventDataBuffer ev{XR_TYPE_FRAME_STATE};
  EXPECT_EQ(xrPollEvent(instance_, &ev), XR_ERROR_VALIDATION_FAILURE);
  create_session();
  XrReferenceSpaceCreateInfo rci{XR_TYPE_ACTION_SPACE_CREATE_INFO};
  rci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rci.poseInReferenceSpace.orientation.w = 1;
  XrSpace space = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateReferenceSpace(session_, &rci, &space), XR_ERROR_VALIDATION_FAILURE);
  XrSessionBeginInfo bi{XR_TYPE_SESSION_CREATE_INFO};
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  EXPECT_EQ(xrBeginSession(session_, &bi), XR_ERROR_VALIDATION_FAILURE);
  XrSessionCreateInfo sci{XR_TYPE_SESSION_BEGIN_INFO};
  XrSession other = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateSession(instance_, &sci, &other), XR_ERROR_VALIDATION_FAILURE);
}

TEST_F(XrTest, InvalidHandles) {
  create_instance();
  create_session();
  const XrSpace local = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  // Garbage, a handle of another type, and a destroyed handle.
  EXPECT_EQ(xrBeginSession(bogus<XrSession>(0xdeadbeef), nullptr), XR_ERROR_HANDLE_INVALID);
  EXPECT_EQ(xrBeginSession(bogus<XrSession>(reinterpret_cast<std::uint64_t>(local)), nullptr), XR_ERROR_HANDLE_INVALID);
  XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
  EXPECT_EQ(xrLocateSpace(local, bogus<XrSpace>(0x12345), 1, &loc), XR_ERROR_HANDLE_INVALID);
  uint32_t n = 0;
  EXPECT_EQ(xrEnumerateSwapchainImages(bogus<XrSwapchain>(0x777), 0, &n, nullptr), XR_ERROR_HANDLE_INVALID);
  ASSERT_EQ(xrDestroySpace(local), XR_SUCCESS);
  EXPECT_EQ(xrDestroySpace(local), XR_ERROR_HANDLE_INVALID);
  XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(asci.actionSetName, "set");
  std::strcpy(asci.localizedActionSetName, "Set");
  XrActionSet set = XR_NULL_HANDLE;
  ASSERT_EQ(xrCreateActionSet(instance_, &asci, &set), XR_SUCCESS);
  ASSERT_EQ(xrDestroyActionSet(set), XR_SUCCESS);
  XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
  std::strcpy(aci.actionName, "a");
  std::strcpy(aci.localizedActionName, "A");
  aci.actionType = XR_ACTION_TYPE_BOOLEAN_INPUT;
  XrAction action = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateAction(set, &aci, &action), XR_ERROR_HANDLE_INVALID);
  // Extension functions: only with the extension enabled; no instance -> handle invalid.
  PFN_xrVoidFunction fn = nullptr;
  EXPECT_EQ(xrGetInstanceProcAddr(instance_, "xrGetVisibilityMaskKHR", &fn), XR_ERROR_FUNCTION_UNSUPPORTED);
  EXPECT_EQ(fn, nullptr);
  EXPECT_EQ(xrGetInstanceProcAddr(instance_, "xrNoSuchFunction", &fn), XR_ERROR_FUNCTION_UNSUPPORTED);
}

TEST_F(XrTest, BadArguments) {
  create_instance();
  XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
  gi.formFactor = XR_FORM_FACTOR_HANDHELD_DISPLAY;
  XrSystemId id = 0;
  EXPECT_EQ(xrGetSystem(instance_, &gi, &id), XR_ERROR_FORM_FACTOR_UNSUPPORTED);
  XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES};
  EXPECT_EQ(xrGetSystemProperties(instance_, system_ + 7, &sp), XR_ERROR_SYSTEM_INVALID);
  uint32_t n = 0;
  EXPECT_EQ(xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO, 0, &n, nullptr),
            XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);
  ASSERT_EQ(xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, &n, nullptr),
            XR_SUCCESS);
  ASSERT_EQ(n, 2u);
  XrViewConfigurationView views[2]{{XR_TYPE_VIEW_CONFIGURATION_VIEW}, {XR_TYPE_VIEW_CONFIGURATION_VIEW}};
  EXPECT_EQ(xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 1, &n, views),
            XR_ERROR_SIZE_INSUFFICIENT);
  ASSERT_EQ(xrEnumerateViewConfigurationViews(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 2, &n, views),
            XR_SUCCESS);
  EXPECT_EQ(views[0].recommendedImageRectWidth, 64u);  // the "tiny" preset
  EXPECT_EQ(views[0].recommendedImageRectHeight, 72u);
  // Paths.
  XrPath p = XR_NULL_PATH;
  EXPECT_EQ(xrStringToPath(instance_, "no/leading/slash", &p), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(xrStringToPath(instance_, "/Upper/case", &p), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(xrStringToPath(instance_, "/double//slash", &p), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(xrStringToPath(instance_, "/trailing/", &p), XR_ERROR_PATH_FORMAT_INVALID);
  char buf[64];
  EXPECT_EQ(xrPathToString(instance_, 987654, sizeof buf, &n, buf), XR_ERROR_PATH_INVALID);
  const XrPath left = path("/user/hand/left");
  EXPECT_EQ(path("/user/hand/left"), left);
  ASSERT_EQ(xrPathToString(instance_, left, sizeof buf, &n, buf), XR_SUCCESS);
  EXPECT_STREQ(buf, "/user/hand/left");
  EXPECT_EQ(n, 16u);
  EXPECT_EQ(xrPathToString(instance_, left, 4, &n, buf), XR_ERROR_SIZE_INSUFFICIENT);

  // Session creation needs the graphics requirements call and a graphics binding.
  XrSessionCreateInfo sci{XR_TYPE_SESSION_CREATE_INFO};
  sci.systemId = system_;
  XrSession s = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateSession(instance_, &sci, &s), XR_ERROR_GRAPHICS_DEVICE_INVALID);
  create_session();
  XrSession second = XR_NULL_HANDLE;
  XrGraphicsBindingVulkan2KHR binding{XR_TYPE_GRAPHICS_BINDING_VULKAN2_KHR};
  binding.instance = vk_instance_;
  binding.physicalDevice = vk_physical_;
  binding.device = vk_device_;
  binding.queueFamilyIndex = 99;
  sci.next = &binding;
  EXPECT_EQ(xrCreateSession(instance_, &sci, &second), XR_ERROR_GRAPHICS_DEVICE_INVALID);

  // Spaces.
  XrReferenceSpaceCreateInfo rci{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rci.poseInReferenceSpace = {{0, 0, 0, 2}, {0, 0, 0}};
  XrSpace space = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateReferenceSpace(session_, &rci, &space), XR_ERROR_POSE_INVALID);
  rci.poseInReferenceSpace = {{0, 0, 0, 1}, {0, 0, 0}};
  rci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_UNBOUNDED_MSFT;
  EXPECT_EQ(xrCreateReferenceSpace(session_, &rci, &space), XR_ERROR_REFERENCE_SPACE_UNSUPPORTED);
  const XrSpace local = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
  EXPECT_EQ(xrLocateSpace(local, local, 0, &loc), XR_ERROR_TIME_INVALID);

  // Swapchains.
  XrSwapchainCreateInfo ci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  ci.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT;
  ci.format = 12345;
  ci.sampleCount = ci.faceCount = ci.arraySize = ci.mipCount = 1;
  ci.width = ci.height = 16;
  XrSwapchain sc = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateSwapchain(session_, &ci, &sc), XR_ERROR_SWAPCHAIN_FORMAT_UNSUPPORTED);
  ci.format = VK_FORMAT_R8G8B8A8_SRGB;
  ci.width = 0;
  EXPECT_EQ(xrCreateSwapchain(session_, &ci, &sc), XR_ERROR_VALIDATION_FAILURE);
}

TEST_F(XrTest, SessionStateMachine) {
  create_instance();
  create_session();
  XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  // READY is queued but not yet observed by the application.
  EXPECT_EQ(xrBeginSession(session_, &bi), XR_ERROR_SESSION_NOT_READY);
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  EXPECT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_ERROR_SESSION_NOT_RUNNING);
  EXPECT_EQ(xrRequestExitSession(session_), XR_ERROR_SESSION_NOT_RUNNING);
  EXPECT_EQ(poll_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_READY}));
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO;
  EXPECT_EQ(xrBeginSession(session_, &bi), XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  ASSERT_EQ(xrBeginSession(session_, &bi), XR_SUCCESS);
  EXPECT_EQ(xrBeginSession(session_, &bi), XR_ERROR_SESSION_RUNNING);
  EXPECT_EQ(xrEndSession(session_), XR_ERROR_SESSION_NOT_STOPPING);
  // Frame call order.
  EXPECT_EQ(xrBeginFrame(session_, nullptr), XR_ERROR_CALL_ORDER_INVALID);
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.displayTime = 1;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  EXPECT_EQ(xrEndFrame(session_, &ei), XR_ERROR_CALL_ORDER_INVALID);
  ASSERT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
  EXPECT_FALSE(fs.shouldRender);  // not yet VISIBLE
  ASSERT_EQ(xrBeginFrame(session_, nullptr), XR_SUCCESS);
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_ADDITIVE;
  EXPECT_EQ(xrEndFrame(session_, &ei), XR_ERROR_ENVIRONMENT_BLEND_MODE_UNSUPPORTED);
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  ei.displayTime = 0;
  EXPECT_EQ(xrEndFrame(session_, &ei), XR_ERROR_TIME_INVALID);
  ei.displayTime = fs.predictedDisplayTime;
  ASSERT_EQ(xrEndFrame(session_, &ei), XR_SUCCESS);
  EXPECT_EQ(poll_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_SYNCHRONIZED, XR_SESSION_STATE_VISIBLE,
                                                        XR_SESSION_STATE_FOCUSED}));
  // A begun frame that is begun again is discarded.
  ASSERT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
  EXPECT_TRUE(fs.shouldRender);
  ASSERT_EQ(xrBeginFrame(session_, nullptr), XR_SUCCESS);
  ASSERT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
  EXPECT_EQ(xrBeginFrame(session_, nullptr), XR_FRAME_DISCARDED);
  ei.displayTime = fs.predictedDisplayTime;
  ASSERT_EQ(xrEndFrame(session_, &ei), XR_SUCCESS);
  // Exit: FOCUSED -> VISIBLE -> SYNCHRONIZED -> STOPPING, then IDLE -> EXITING.
  ASSERT_EQ(xrRequestExitSession(session_), XR_SUCCESS);
  EXPECT_EQ(poll_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_SYNCHRONIZED,
                                                        XR_SESSION_STATE_STOPPING}));
  ASSERT_EQ(xrEndSession(session_), XR_SUCCESS);
  EXPECT_EQ(xrEndSession(session_), XR_ERROR_SESSION_NOT_RUNNING);
  EXPECT_EQ(poll_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_EXITING}));
}

TEST_F(XrTest, ExitAfterFrames) {
  setenv("FOVEA_EXIT_AFTER_FRAMES", "3", 1);
  create_instance();
  run_to_focused();
  ASSERT_EQ(frame(), XR_SUCCESS);
  EXPECT_TRUE(poll_states().empty());
  ASSERT_EQ(frame(), XR_SUCCESS);  // the third frame
  EXPECT_EQ(poll_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_VISIBLE, XR_SESSION_STATE_SYNCHRONIZED,
                                                        XR_SESSION_STATE_STOPPING}));
  ASSERT_EQ(xrEndSession(session_), XR_SUCCESS);
  EXPECT_EQ(poll_states(), (std::vector<XrSessionState>{XR_SESSION_STATE_IDLE, XR_SESSION_STATE_EXITING}));
}

// Lockstep pacing: consecutive frames are exactly one period apart however loaded the host
// (realtime pacing: XrTest.DisplayClockThrottles, XrTest.PacingNeverPredictsThePast).
TEST_F(XrTest, DisplayClock) {
  setenv("FOVEA_RUNTIME_PACING", "lockstep", 1);
  create_instance();
  run_to_focused();
  XrFrameState a{XR_TYPE_FRAME_STATE}, b{XR_TYPE_FRAME_STATE};
  ASSERT_EQ(frame({}, &a), XR_SUCCESS);
  ASSERT_EQ(frame({}, &b), XR_SUCCESS);
  EXPECT_EQ(a.predictedDisplayPeriod, 14285714);  // 70 Hz
  EXPECT_EQ(b.predictedDisplayTime - a.predictedDisplayTime, a.predictedDisplayPeriod);
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  const XrTime t_now = XrTime(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
  EXPECT_GT(b.predictedDisplayTime, t_now - 1'000'000'000);
  EXPECT_LT(b.predictedDisplayTime, t_now + 1'000'000'000);
}

// Realtime pacing (the default): an application faster than the display is paced by
// xrWaitFrame, whatever happened before: each wait sleeps until its wake time, a period
// after the previous one (lockstep lets an application that was late catch up unpaced).
TEST_F(XrTest, DisplayClockThrottles) {
  create_instance();
  run_to_focused();
  XrFrameState a{XR_TYPE_FRAME_STATE};
  ASSERT_EQ(frame({}, &a), XR_SUCCESS);
  // An application faster than the display is paced by xrWaitFrame: 10 frames take at
  // least 9 periods of wall time.
  const auto mono = [] {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return XrTime(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
  };
  const XrTime start = mono();
  for (int i = 0; i < 10; ++i) {
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    ASSERT_EQ(frame({}, &fs), XR_SUCCESS);
  }
  EXPECT_GE(mono() - start, 9 * a.predictedDisplayPeriod);
}

TEST_F(XrTest, SpacesAndViews) {
  create_instance();
  run_to_focused();
  const XrSpace local = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  const XrSpace stage = reference_space(XR_REFERENCE_SPACE_TYPE_STAGE);
  const XrSpace view = reference_space(XR_REFERENCE_SPACE_TYPE_VIEW);
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  ASSERT_EQ(frame({}, &fs), XR_SUCCESS);
  XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
  ASSERT_EQ(xrLocateSpace(local, stage, fs.predictedDisplayTime, &loc), XR_SUCCESS);
  EXPECT_NEAR(loc.pose.position.y, 1.6, 1e-6);  // LOCAL at eye height above the floor
  EXPECT_EQ(loc.locationFlags & XR_SPACE_LOCATION_POSITION_VALID_BIT, XR_SPACE_LOCATION_POSITION_VALID_BIT);
  XrExtent2Df bounds;
  EXPECT_EQ(xrGetReferenceSpaceBoundsRect(session_, XR_REFERENCE_SPACE_TYPE_STAGE, &bounds), XR_SUCCESS);
  EXPECT_EQ(xrGetReferenceSpaceBoundsRect(session_, XR_REFERENCE_SPACE_TYPE_LOCAL, &bounds), XR_SPACE_BOUNDS_UNAVAILABLE);

  // Views: both eyes valid, IPD apart, the preset's FOV; the head moves slowly.
  XrViewLocateInfo li{XR_TYPE_VIEW_LOCATE_INFO};
  li.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  li.displayTime = fs.predictedDisplayTime;
  li.space = view;
  XrViewState vs{XR_TYPE_VIEW_STATE};
  XrView views[2]{{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
  uint32_t n = 0;
  EXPECT_EQ(xrLocateViews(session_, &li, &vs, 1, &n, views), XR_ERROR_SIZE_INSUFFICIENT);
  ASSERT_EQ(xrLocateViews(session_, &li, &vs, 2, &n, views), XR_SUCCESS);
  EXPECT_EQ(vs.viewStateFlags & (XR_VIEW_STATE_ORIENTATION_VALID_BIT | XR_VIEW_STATE_POSITION_VALID_BIT),
            XrViewStateFlags(XR_VIEW_STATE_ORIENTATION_VALID_BIT | XR_VIEW_STATE_POSITION_VALID_BIT));
  EXPECT_NEAR(views[1].pose.position.x - views[0].pose.position.x, 0.063, 1e-6);
  EXPECT_NEAR(views[0].fov.angleLeft, -50.0 * M_PI / 180, 1e-5);
  li.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO;
  EXPECT_EQ(xrLocateViews(session_, &li, &vs, 2, &n, views), XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);

  // The scripted head pose is a function of time since the display epoch: locating the
  // same time twice gives the same pose; two seconds later it has turned.
  XrSpaceLocation a{XR_TYPE_SPACE_LOCATION}, b{XR_TYPE_SPACE_LOCATION}, c{XR_TYPE_SPACE_LOCATION};
  ASSERT_EQ(xrLocateSpace(view, local, fs.predictedDisplayTime, &a), XR_SUCCESS);
  ASSERT_EQ(xrLocateSpace(view, local, fs.predictedDisplayTime, &b), XR_SUCCESS);
  ASSERT_EQ(xrLocateSpace(view, local, fs.predictedDisplayTime + 2'000'000'000, &c), XR_SUCCESS);
  EXPECT_EQ(std::memcmp(&a.pose, &b.pose, sizeof a.pose), 0);
  EXPECT_GT(std::abs(c.pose.orientation.y - a.pose.orientation.y), 0.01);
}

TEST_F(XrTest, SwapchainAcquireWaitRelease) {
  create_instance();
  run_to_focused();
  uint32_t n = 0;
  ASSERT_EQ(xrEnumerateSwapchainFormats(session_, 0, &n, nullptr), XR_SUCCESS);
  std::vector<int64_t> formats(n);
  ASSERT_EQ(xrEnumerateSwapchainFormats(session_, n, &n, formats.data()), XR_SUCCESS);
  EXPECT_EQ(formats[0], VK_FORMAT_R8G8B8A8_SRGB);
  const XrSwapchain sc = color_swapchain(64, 72);
  ASSERT_EQ(xrEnumerateSwapchainImages(sc, 0, &n, nullptr), XR_SUCCESS);
  ASSERT_EQ(n, 3u);
  std::vector<XrSwapchainImageVulkan2KHR> images(n, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
  ASSERT_EQ(xrEnumerateSwapchainImages(sc, n, &n, reinterpret_cast<XrSwapchainImageBaseHeader*>(images.data())),
            XR_SUCCESS);
  EXPECT_NE(images[0].image, VK_NULL_HANDLE);
  std::vector<XrSwapchainImageVulkan2KHR> wrong(n, {XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO});
  EXPECT_EQ(xrEnumerateSwapchainImages(sc, n, &n, reinterpret_cast<XrSwapchainImageBaseHeader*>(wrong.data())),
            XR_ERROR_VALIDATION_FAILURE);

  XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
  wi.timeout = XR_INFINITE_DURATION;
  EXPECT_EQ(xrWaitSwapchainImage(sc, &wi), XR_ERROR_CALL_ORDER_INVALID);
  EXPECT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_ERROR_CALL_ORDER_INVALID);
  uint32_t idx[4];
  for (int i = 0; i < 3; ++i) ASSERT_EQ(xrAcquireSwapchainImage(sc, nullptr, &idx[i]), XR_SUCCESS);
  EXPECT_EQ(idx[0], 0u);
  EXPECT_EQ(idx[1], 1u);
  EXPECT_EQ(xrAcquireSwapchainImage(sc, nullptr, &idx[3]), XR_ERROR_CALL_ORDER_INVALID);  // all acquired
  EXPECT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_ERROR_CALL_ORDER_INVALID);          // not waited
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
    ASSERT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
  }

  // Layers: a released swapchain with a valid rect is accepted, a bad rect or an
  // unreleased swapchain is not.
  const XrSpace local = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  StereoLayer stereo(sc, local);
  auto& pv = stereo.views;
  auto& layer = stereo.layer;
  const std::vector<const XrCompositionLayerBaseHeader*> layers{stereo.header()};
  EXPECT_EQ(frame(layers), XR_SUCCESS);
  pv[1].subImage.imageRect = {{1, 0}, {64, 72}};
  EXPECT_EQ(frame(layers), XR_ERROR_SWAPCHAIN_RECT_INVALID);
  pv[1].subImage.imageRect = {{0, 0}, {64, 72}};
  layer.viewCount = 1;
  EXPECT_EQ(frame(layers), XR_ERROR_VALIDATION_FAILURE);
  layer.viewCount = 2;
  const XrSwapchain fresh = color_swapchain(64, 72);
  pv[0].subImage.swapchain = fresh;
  EXPECT_EQ(frame(layers), XR_ERROR_LAYER_INVALID);
  const std::vector<const XrCompositionLayerBaseHeader*> null_layer{nullptr};
  EXPECT_EQ(frame(null_layer), XR_ERROR_LAYER_INVALID);
}

// Acquires, waits and releases one image of `sc`.
void cycle(XrSwapchain sc) {
  uint32_t i = 0;
  ASSERT_EQ(xrAcquireSwapchainImage(sc, nullptr, &i), XR_SUCCESS);
  XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
  wi.timeout = XR_INFINITE_DURATION;
  ASSERT_EQ(xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
  ASSERT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
}

TEST_F(XrTest, CompositionLayerDepthAccepted) {
  create_instance({XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME});
  run_to_focused();
  const XrSwapchain color = color_swapchain(64, 72);
  XrSwapchainCreateInfo ci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
  ci.usageFlags = XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  ci.format = VK_FORMAT_D32_SFLOAT;
  ci.sampleCount = ci.faceCount = ci.arraySize = ci.mipCount = 1;
  ci.width = 64;
  ci.height = 72;
  XrSwapchain depth = XR_NULL_HANDLE;
  ASSERT_EQ(xrCreateSwapchain(session_, &ci, &depth), XR_SUCCESS);
  cycle(color);
  cycle(depth);
  XrCompositionLayerDepthInfoKHR di[2];
  XrCompositionLayerProjectionView pv[2];
  for (int i = 0; i < 2; ++i) {
    di[i] = {XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR};
    di[i].subImage.swapchain = depth;
    di[i].subImage.imageRect = {{0, 0}, {64, 72}};
    di[i].minDepth = 0;
    di[i].maxDepth = 1;
    di[i].nearZ = 0.1f;
    di[i].farZ = 100;
    pv[i] = {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW};
    pv[i].next = &di[i];
    pv[i].pose.orientation.w = 1;
    pv[i].fov = {-0.8f, 0.8f, 0.8f, -0.8f};
    pv[i].subImage.swapchain = color;
    pv[i].subImage.imageRect = {{0, 0}, {64, 72}};
  }
  XrCompositionLayerProjection layer{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  layer.space = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  layer.viewCount = 2;
  layer.views = pv;
  const std::vector<const XrCompositionLayerBaseHeader*> layers{
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&layer)};
  EXPECT_EQ(frame(layers), XR_SUCCESS);
  di[1].minDepth = 0.9f;
  di[1].maxDepth = 0.1f;
  EXPECT_EQ(frame(layers), XR_ERROR_VALIDATION_FAILURE);
  di[1].minDepth = 0;
  di[1].maxDepth = 1;
  di[1].subImage.swapchain = color;  // a colour swapchain as depth
  EXPECT_EQ(frame(layers), XR_ERROR_VALIDATION_FAILURE);
  di[1].subImage.swapchain = depth;
  // nearZ, farZ in (0, +infinity], not equal: infinite planes (also reversed) are valid.
  di[1].farZ = std::numeric_limits<float>::infinity();
  EXPECT_EQ(frame(layers), XR_SUCCESS);
  di[1].nearZ = std::numeric_limits<float>::infinity();
  di[1].farZ = 0.1f;
  EXPECT_EQ(frame(layers), XR_SUCCESS);
  for (float bad_z : {0.0f, -1.0f, std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::infinity()}) {
    di[1].nearZ = bad_z;
    EXPECT_EQ(frame(layers), XR_ERROR_VALIDATION_FAILURE) << bad_z;
  }
  di[1].nearZ = di[1].farZ = 1.0f;
  EXPECT_EQ(frame(layers), XR_ERROR_VALIDATION_FAILURE);
  // A colour format with depth usage is refused at creation.
  ci.format = VK_FORMAT_R8G8B8A8_SRGB;
  XrSwapchain bad = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateSwapchain(session_, &ci, &bad), XR_ERROR_FEATURE_UNSUPPORTED);
}

TEST_F(XrTest, ControllerBindingsAcceptedButInactive) {
  create_instance();
  create_session();
  XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(asci.actionSetName, "gameplay");
  std::strcpy(asci.localizedActionSetName, "Gameplay");
  XrActionSet set = XR_NULL_HANDLE;
  ASSERT_EQ(xrCreateActionSet(instance_, &asci, &set), XR_SUCCESS);
  EXPECT_EQ(xrCreateActionSet(instance_, &asci, &set), XR_ERROR_NAME_DUPLICATED);
  const XrPath hands[2] = {path("/user/hand/left"), path("/user/hand/right")};
  XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
  std::strcpy(aci.actionName, "hand_pose");
  std::strcpy(aci.localizedActionName, "Hand Pose");
  aci.actionType = XR_ACTION_TYPE_POSE_INPUT;
  aci.countSubactionPaths = 2;
  aci.subactionPaths = hands;
  XrAction pose = XR_NULL_HANDLE;
  ASSERT_EQ(xrCreateAction(set, &aci, &pose), XR_SUCCESS);
  std::strcpy(aci.actionName, "Bad Name");
  XrAction bad = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateAction(set, &aci, &bad), XR_ERROR_PATH_FORMAT_INVALID);
  for (const char* profile : {"/interaction_profiles/khr/simple_controller", "/interaction_profiles/oculus/touch_controller",
                              "/interaction_profiles/htc/vive_controller", "/interaction_profiles/valve/index_controller",
                              "/interaction_profiles/microsoft/motion_controller"}) {
    XrActionSuggestedBinding b[2] = {{pose, path("/user/hand/left/input/grip/pose")},
                                     {pose, path("/user/hand/right/input/grip/pose")}};
    XrInteractionProfileSuggestedBinding s{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    s.interactionProfile = path(profile);
    s.countSuggestedBindings = 2;
    s.suggestedBindings = b;
    EXPECT_EQ(xrSuggestInteractionProfileBindings(instance_, &s), XR_SUCCESS) << profile;
  }
  XrActionSuggestedBinding wrong{pose, path("/user/gamepad/input/a/click")};
  XrInteractionProfileSuggestedBinding s{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  s.interactionProfile = path("/interaction_profiles/khr/simple_controller");
  s.countSuggestedBindings = 1;
  s.suggestedBindings = &wrong;
  EXPECT_EQ(xrSuggestInteractionProfileBindings(instance_, &s), XR_ERROR_PATH_UNSUPPORTED);
  s.interactionProfile = path("/interaction_profiles/no/such_device");
  EXPECT_EQ(xrSuggestInteractionProfileBindings(instance_, &s), XR_ERROR_PATH_UNSUPPORTED);

  XrActionStateGetInfo gi{XR_TYPE_ACTION_STATE_GET_INFO};
  gi.action = pose;
  XrActionStatePose st{XR_TYPE_ACTION_STATE_POSE};
  EXPECT_EQ(xrGetActionStatePose(session_, &gi, &st), XR_ERROR_ACTIONSET_NOT_ATTACHED);
  XrSessionActionSetsAttachInfo ai{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  ai.countActionSets = 1;
  ai.actionSets = &set;
  ASSERT_EQ(xrAttachSessionActionSets(session_, &ai), XR_SUCCESS);
  EXPECT_EQ(xrAttachSessionActionSets(session_, &ai), XR_ERROR_ACTIONSETS_ALREADY_ATTACHED);
  ASSERT_EQ(xrGetActionStatePose(session_, &gi, &st), XR_SUCCESS);
  EXPECT_FALSE(st.isActive);
  XrActionStateBoolean sb{XR_TYPE_ACTION_STATE_BOOLEAN};
  EXPECT_EQ(xrGetActionStateBoolean(session_, &gi, &sb), XR_ERROR_ACTION_TYPE_MISMATCH);
  gi.subactionPath = path("/user/head");
  EXPECT_EQ(xrGetActionStatePose(session_, &gi, &st), XR_ERROR_PATH_UNSUPPORTED);
  XrInteractionProfileState ips{XR_TYPE_INTERACTION_PROFILE_STATE};
  ASSERT_EQ(xrGetCurrentInteractionProfile(session_, hands[0], &ips), XR_SUCCESS);
  EXPECT_EQ(ips.interactionProfile, XrPath(XR_NULL_PATH));
  // Controllers are never tracked.
  XrActionSpaceCreateInfo sci{XR_TYPE_ACTION_SPACE_CREATE_INFO};
  sci.action = pose;
  sci.subactionPath = hands[0];
  sci.poseInActionSpace.orientation.w = 1;
  XrSpace hand = XR_NULL_HANDLE;
  ASSERT_EQ(xrCreateActionSpace(session_, &sci, &hand), XR_SUCCESS);
  XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
  ASSERT_EQ(xrLocateSpace(hand, reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL), 1000, &loc), XR_SUCCESS);
  EXPECT_EQ(loc.locationFlags, 0u);
  XrActiveActionSet active{set, XR_NULL_PATH};
  XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  EXPECT_EQ(xrSyncActions(session_, &sync), XR_SESSION_NOT_FOCUSED);
}

// An eye gaze pose action in a new action set `set`, suggested on the eye gaze interaction
// profile and attached to the session.
XrAction attach_gaze_action(XrInstance instance, XrSession session, XrActionSet* set_out) {
  XrActionSetCreateInfo asci{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(asci.actionSetName, "eyes");
  std::strcpy(asci.localizedActionSetName, "Eyes");
  XrActionSet set = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateActionSet(instance, &asci, &set), XR_SUCCESS);
  XrActionCreateInfo aci{XR_TYPE_ACTION_CREATE_INFO};
  std::strcpy(aci.actionName, "gaze");
  std::strcpy(aci.localizedActionName, "Gaze");
  aci.actionType = XR_ACTION_TYPE_POSE_INPUT;
  XrAction gaze = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateAction(set, &aci, &gaze), XR_SUCCESS);
  XrPath binding = XR_NULL_PATH, profile = XR_NULL_PATH;
  EXPECT_EQ(xrStringToPath(instance, "/user/eyes_ext/input/gaze_ext/pose", &binding), XR_SUCCESS);
  EXPECT_EQ(xrStringToPath(instance, "/interaction_profiles/ext/eye_gaze_interaction", &profile), XR_SUCCESS);
  XrActionSuggestedBinding b{gaze, binding};
  XrInteractionProfileSuggestedBinding s{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
  s.interactionProfile = profile;
  s.countSuggestedBindings = 1;
  s.suggestedBindings = &b;
  EXPECT_EQ(xrSuggestInteractionProfileBindings(instance, &s), XR_SUCCESS);
  XrSessionActionSetsAttachInfo ai{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  ai.countActionSets = 1;
  ai.actionSets = &set;
  EXPECT_EQ(xrAttachSessionActionSets(session, &ai), XR_SUCCESS);
  *set_out = set;
  return gaze;
}

// An eye gaze action bound to the eye gaze interaction profile, attached and synced; the
// session must be running. Returns the action space.
XrSpace make_gaze_space(XrInstance instance, XrSession session) {
  XrActionSet set = XR_NULL_HANDLE;
  const XrAction gaze = attach_gaze_action(instance, session, &set);
  XrActiveActionSet active{set, XR_NULL_PATH};
  XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  EXPECT_EQ(xrSyncActions(session, &sync), XR_SUCCESS);
  XrEventDataBuffer ev{XR_TYPE_EVENT_DATA_BUFFER};
  EXPECT_EQ(xrPollEvent(instance, &ev), XR_SUCCESS);
  EXPECT_EQ(ev.type, XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED);
  XrInteractionProfileState ips{XR_TYPE_INTERACTION_PROFILE_STATE};
  XrPath eyes = XR_NULL_PATH;
  EXPECT_EQ(xrStringToPath(instance, "/user/eyes_ext", &eyes), XR_SUCCESS);
  EXPECT_EQ(xrGetCurrentInteractionProfile(session, eyes, &ips), XR_SUCCESS);
  XrPath profile = XR_NULL_PATH;
  EXPECT_EQ(xrStringToPath(instance, "/interaction_profiles/ext/eye_gaze_interaction", &profile), XR_SUCCESS);
  EXPECT_EQ(ips.interactionProfile, profile);
  XrActionStateGetInfo gi{XR_TYPE_ACTION_STATE_GET_INFO};
  gi.action = gaze;
  XrActionStatePose st{XR_TYPE_ACTION_STATE_POSE};
  EXPECT_EQ(xrGetActionStatePose(session, &gi, &st), XR_SUCCESS);
  EXPECT_TRUE(st.isActive);
  XrActionSpaceCreateInfo sci{XR_TYPE_ACTION_SPACE_CREATE_INFO};
  sci.action = gaze;
  sci.poseInActionSpace.orientation.w = 1;
  XrSpace space = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateActionSpace(session, &sci, &space), XR_SUCCESS);
  return space;
}

XrTime mono_now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return XrTime(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// The gaze pose's forward direction (-Z rotated by the orientation).
glm::dvec3 forward(const XrQuaternionf& q) {
  return glm::dquat(q.w, q.x, q.y, q.z) * glm::dvec3(0, 0, -1);
}

// The display model's compositor budget (xrcommon DisplayParams: max(period / 5, 3 ms)):
// xrWaitFrame wakes the application one period plus this before the predicted display time.
XrTime wake_time(const XrFrameState& fs) {
  return fs.predictedDisplayTime - fs.predictedDisplayPeriod - std::max<XrTime>(fs.predictedDisplayPeriod / 5, 3'000'000);
}

TEST_F(XrTest, EyeGaze) {
  create_instance({XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME});
  XrSystemEyeGazeInteractionPropertiesEXT eg{XR_TYPE_SYSTEM_EYE_GAZE_INTERACTION_PROPERTIES_EXT};
  XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES};
  sp.next = &eg;
  ASSERT_EQ(xrGetSystemProperties(instance_, system_, &sp), XR_SUCCESS);
  EXPECT_TRUE(eg.supportsEyeGazeInteraction);
  run_to_focused();
  const XrSpace gaze_space = make_gaze_space(instance_, session_);
  const XrSpace view = reference_space(XR_REFERENCE_SPACE_TYPE_VIEW);
  // Over 100 frames the synthetic 120 Hz tracker reports valid gaze most of the time (blinks
  // and dropouts are invalid). Located for the frame's display time, a valid gaze carries the
  // validity and tracking bits, a forward direction and the time of the newest sample
  // measured by the call (realtime: the read time is now), never a later one: within one
  // sample period (8.33 ms) before the call. (The runtime used to give the sample at the
  // display time, up to a frame in the future.)
  int valid = 0;
  for (int i = 0; i < 100; ++i) {
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    ASSERT_EQ(frame({}, &fs), XR_SUCCESS);
    XrEyeGazeSampleTimeEXT when{XR_TYPE_EYE_GAZE_SAMPLE_TIME_EXT};
    XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
    loc.next = &when;
    const XrTime before = mono_now();
    ASSERT_EQ(xrLocateSpace(gaze_space, view, fs.predictedDisplayTime + fs.predictedDisplayPeriod, &loc), XR_SUCCESS);
    const XrTime after = mono_now();
    if (loc.locationFlags & XR_SPACE_LOCATION_ORIENTATION_VALID_BIT) {
      ++valid;
      EXPECT_TRUE(loc.locationFlags & XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT);
      EXPECT_LE(when.time, after);
      EXPECT_GT(when.time, before - 8'333'334);
      EXPECT_LT(forward(loc.pose.orientation).z, -0.5);
    } else {
      EXPECT_EQ(loc.locationFlags, 0u);
      EXPECT_EQ(when.time, 0);
    }
  }
  EXPECT_GT(valid, 75);
}

// A 100 Hz recording of a 20 deg gaze with a blink at 1.0-1.2 s, in lockstep.
std::string write_replay(const std::string& dir) {
  const std::string file = dir + "/gaze.csv";
  std::ofstream out(file);
  out << "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n";
  const double yaw = 20.0 * M_PI / 180;  // to the right
  for (int i = 0; i <= 200; ++i) {
    const bool blink = i >= 100 && i < 120;  // 1.0 s .. 1.2 s
    out << std::int64_t(i) * 10'000'000 << ",combined," << std::sin(yaw) << ",0," << -std::cos(yaw) << ","
        << (blink ? 0.0 : 1.0) << "," << (blink ? 2 : 1) << "\n";
  }
  return file;
}

// FOVEA_GAZE=replay:FILE: a recording starts at the display epoch; the gaze space follows it,
// blinks are invalid. In lockstep the runtime reads the tracker at the newest frame's wake
// time: a located gaze is the newest sample by then (between samples: the one before), even
// for a later display time, and a time before the wake gets the samples measured by it.
// (The runtime used to return the sample at the time asked for, in the future.)
TEST_F(XrTest, EyeGazeReplay) {
  TempDir dir("gaze_replay");
  setenv("FOVEA_GAZE", ("replay:" + write_replay(dir.path())).c_str(), 1);
  setenv("FOVEA_RUNTIME_PACING", "lockstep", 1);  // frame 1 at the epoch plus one period
  create_instance({XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME});
  unsetenv("FOVEA_GAZE");
  run_to_focused();
  const XrSpace gaze_space = make_gaze_space(instance_, session_);
  const XrSpace view = reference_space(XR_REFERENCE_SPACE_TYPE_VIEW);
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  ASSERT_EQ(frame({}, &fs), XR_SUCCESS);  // frame 1: epoch = its display time - one period
  const XrTime epoch = fs.predictedDisplayTime - fs.predictedDisplayPeriod;
  XrEyeGazeSampleTimeEXT when{XR_TYPE_EYE_GAZE_SAMPLE_TIME_EXT};
  XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
  loc.next = &when;
  while (wake_time(fs) < epoch + 510'000'000) ASSERT_EQ(frame({}, &fs), XR_SUCCESS);
  const XrTime wake = wake_time(fs);
  ASSERT_EQ(xrLocateSpace(gaze_space, view, fs.predictedDisplayTime, &loc), XR_SUCCESS);
  ASSERT_TRUE(loc.locationFlags & XR_SPACE_LOCATION_ORIENTATION_VALID_BIT);
  const glm::dvec3 f = forward(loc.pose.orientation);
  EXPECT_NEAR(f.x, std::sin(20.0 * M_PI / 180), 1e-4);
  EXPECT_NEAR(f.y, 0.0, 1e-4);
  EXPECT_EQ(when.time, epoch + (wake - epoch) / 10'000'000 * 10'000'000);  // the newest sample by the wake
  EXPECT_LT(when.time, fs.predictedDisplayTime - fs.predictedDisplayPeriod);
  // Between samples, before the wake: the newest sample measured by then.
  ASSERT_EQ(xrLocateSpace(gaze_space, view, epoch + 507'000'000, &loc), XR_SUCCESS);
  ASSERT_TRUE(loc.locationFlags & XR_SPACE_LOCATION_ORIENTATION_VALID_BIT);
  EXPECT_EQ(when.time, epoch + 500'000'000);
  // A blink is seen once the tracker has delivered it.
  ASSERT_EQ(xrLocateSpace(gaze_space, view, epoch + 1'100'000'000, &loc), XR_SUCCESS);
  EXPECT_TRUE(loc.locationFlags & XR_SPACE_LOCATION_ORIENTATION_VALID_BIT);  // not read yet
  while (wake_time(fs) < epoch + 1'100'000'000) ASSERT_EQ(frame({}, &fs), XR_SUCCESS);
  ASSERT_EQ(xrLocateSpace(gaze_space, view, epoch + 1'100'000'000, &loc), XR_SUCCESS);
  EXPECT_EQ(loc.locationFlags, 0u);  // blink
}

// The runtime's timing records (lockstep, a replay behind an ideal tracker model with a
// 20 ms delay): the gaze sample read at the frame's wake time and delivered by then, its
// delay, the head pose's read and predicted-for times from xrLocateViews, and the true gaze
// at photon time (the recording without the tracker's delay) with the foveal error it gives.
TEST_F(XrTest, TimingRecordsCarryReadTimesAndTheTruth) {
  TempDir dir("gaze_records");
  // 100 Hz, yaw 0.1 deg per sample: the true gaze moves 10 deg/s to the right.
  const std::string file = dir.path() + "/pursuit.csv";
  {
    std::ofstream out(file);
    out << "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n";
    for (int i = 0; i <= 300; ++i) {
      const double yaw = 0.1 * i * M_PI / 180;
      out << std::int64_t(i) * 10'000'000 << ",combined," << std::sin(yaw) << ",0," << -std::cos(yaw) << ",1,1\n";
    }
  }
  setenv("FOVEA_GAZE",
         ("replay:" + file + "?predict=none&tracker=ideal&tracker_rate=100&tracker_delay=20ms&tracker_jitter=0").c_str(), 1);
  setenv("FOVEA_RUNTIME_PACING", "lockstep", 1);
  setenv("FOVEA_RUNTIME_OUT", dir.path().c_str(), 1);
  create_instance({XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME});
  unsetenv("FOVEA_GAZE");
  unsetenv("FOVEA_RUNTIME_OUT");
  run_to_focused();
  const XrSpace local = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  XrTime period = 0;
  for (int i = 0; i < 40; ++i) {
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    ASSERT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
    period = fs.predictedDisplayPeriod;
    XrViewLocateInfo li{XR_TYPE_VIEW_LOCATE_INFO};
    li.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    li.displayTime = fs.predictedDisplayTime;
    li.space = local;
    XrViewState vs{XR_TYPE_VIEW_STATE};
    XrView views[2] = {{XR_TYPE_VIEW}, {XR_TYPE_VIEW}};
    uint32_t n = 0;
    ASSERT_EQ(xrLocateViews(session_, &li, &vs, 2, &n, views), XR_SUCCESS);
    ASSERT_EQ(xrBeginFrame(session_, nullptr), XR_SUCCESS);
    XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
    ei.displayTime = fs.predictedDisplayTime;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    ASSERT_EQ(xrEndFrame(session_, &ei), XR_SUCCESS);
  }
  xrDestroySession(session_);
  session_ = XR_NULL_HANDLE;
  std::ifstream in(dir.path() + "/timing.jsonl");
  std::vector<xrcommon::TimingRecord> records;
  for (std::string line; std::getline(in, line);) records.push_back(xrcommon::parse_timing_record(line, "timing.jsonl"));
  ASSERT_EQ(records.size(), 41u);  // run_to_focused's frame and these
  const XrTime epoch = *records[1].predicted_display_ns - period;
  const XrTime budget = std::max<XrTime>(period / 5, 3'000'000);
  int measured = 0;
  for (std::size_t i = 1; i < records.size(); ++i) {
    const xrcommon::TimingRecord& r = records[i];
    SCOPED_TRACE(r.frame);
    ASSERT_TRUE(r.predicted_display_ns && r.gaze_read_ns && r.photon_ns);
    const XrTime read = *r.predicted_display_ns - period - budget;  // the frame's wake time
    EXPECT_EQ(*r.gaze_read_ns, read);
    ASSERT_TRUE(r.head_pose_ns && r.head_pose_target_ns);
    EXPECT_EQ(*r.head_pose_ns, read);
    EXPECT_EQ(*r.head_pose_target_ns, *r.predicted_display_ns);
    // The truth: the recording at the left eye's photon time (global panel: the vsync).
    const XrTime photon = (*r.photon_ns)[0].mid;
    ASSERT_TRUE(r.true_gaze_dir);
    const double true_yaw = 0.1 * double((photon - epoch) / 10'000'000);
    EXPECT_NEAR(std::atan2(r.true_gaze_dir->x, -r.true_gaze_dir->z) * 180 / M_PI, true_yaw, 1e-4);
    if (!r.gaze_sample_ns) continue;  // nothing delivered yet
    ++measured;
    EXPECT_EQ(*r.gaze_receive_ns - *r.gaze_sample_ns, 20'000'000);
    EXPECT_LE(*r.gaze_receive_ns, read);
    EXPECT_GT(*r.gaze_receive_ns, read - 10'000'000);  // the newest delivered
    ASSERT_TRUE(r.fovea_dir && r.foveal_error_deg());
    const double fovea_yaw = 0.1 * double((*r.gaze_sample_ns - epoch) / 10'000'000);
    EXPECT_NEAR(std::atan2(r.fovea_dir->x, -r.fovea_dir->z) * 180 / M_PI, fovea_yaw, 1e-4);
    EXPECT_NEAR(*r.foveal_error_deg(), true_yaw - fovea_yaw, 1e-3);
    EXPECT_GT(*r.foveal_error_deg(), 0.2);  // 20 ms delay + the wait to the photons at 10 deg/s
  }
  EXPECT_GT(measured, 30);
}

TEST_F(XrTest, VisibilityMask) {
  create_instance({XR_KHR_VISIBILITY_MASK_EXTENSION_NAME});
  create_session();
  auto get = proc<PFN_xrGetVisibilityMaskKHR>("xrGetVisibilityMaskKHR");
  XrVisibilityMaskKHR m{XR_TYPE_VISIBILITY_MASK_KHR};
  EXPECT_EQ(get(session_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 2, XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR, &m),
            XR_ERROR_VALIDATION_FAILURE);
  EXPECT_EQ(get(session_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_MONO, 0, XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR, &m),
            XR_ERROR_VIEW_CONFIGURATION_TYPE_UNSUPPORTED);
  XrVisibilityMaskKHR wrong{XR_TYPE_VIEW};
  EXPECT_EQ(get(session_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR,
                &wrong),
            XR_ERROR_VALIDATION_FAILURE);
  for (auto type : {XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR, XR_VISIBILITY_MASK_TYPE_VISIBLE_TRIANGLE_MESH_KHR,
                    XR_VISIBILITY_MASK_TYPE_LINE_LOOP_KHR}) {
    m = {XR_TYPE_VISIBILITY_MASK_KHR};
    ASSERT_EQ(get(session_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, type, &m), XR_SUCCESS);
    // The preset's lens hides the panel corners: every mesh is non-empty.
    ASSERT_GT(m.vertexCountOutput, 2u) << type;
    ASSERT_GT(m.indexCountOutput, 2u) << type;
    std::vector<XrVector2f> v(m.vertexCountOutput);
    std::vector<uint32_t> idx(m.indexCountOutput);
    m.vertexCapacityInput = m.vertexCountOutput - 1;
    m.indexCapacityInput = m.indexCountOutput;
    m.vertices = v.data();
    m.indices = idx.data();
    EXPECT_EQ(get(session_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, type, &m), XR_ERROR_SIZE_INSUFFICIENT);
    m.vertexCapacityInput = uint32_t(v.size());
    ASSERT_EQ(get(session_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, type, &m), XR_SUCCESS);
    if (type != XR_VISIBILITY_MASK_TYPE_LINE_LOOP_KHR) {
      EXPECT_EQ(idx.size() % 3, 0u);
    }
    const float tan50 = float(std::tan(50.0 * M_PI / 180));
    for (uint32_t i : idx) ASSERT_LT(i, v.size());
    for (const auto& p : v) {  // within the FOV rectangle on the z = -1 plane
      EXPECT_LE(std::abs(p.x), tan50 * 1.0001f);
      EXPECT_TRUE(std::isfinite(p.y));
    }
  }
}

// Findings of the OpenXR conformance suite (CTS 1.1.41, --apiVersion 1.0), reproduced.

// Once an image has been waited on, it must be released before the next wait (core spec,
// xrWaitSwapchainImage); more acquires than images fail; release follows wait.
TEST_F(XrTest, CtsSwapchainWaitTwiceBeforeRelease) {
  create_instance();
  run_to_focused();
  const XrSwapchain sc = color_swapchain(64, 72);
  XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
  wi.timeout = XR_INFINITE_DURATION;
  uint32_t i = 0;
  ASSERT_EQ(xrAcquireSwapchainImage(sc, nullptr, &i), XR_SUCCESS);
  ASSERT_EQ(xrAcquireSwapchainImage(sc, nullptr, &i), XR_SUCCESS);
  ASSERT_EQ(xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
  EXPECT_EQ(xrWaitSwapchainImage(sc, &wi), XR_ERROR_CALL_ORDER_INVALID);  // first not released
  ASSERT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
  EXPECT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_ERROR_CALL_ORDER_INVALID);  // second not waited
  ASSERT_EQ(xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
  EXPECT_EQ(xrWaitSwapchainImage(sc, &wi), XR_ERROR_CALL_ORDER_INVALID);
  ASSERT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
  EXPECT_EQ(xrWaitSwapchainImage(sc, &wi), XR_ERROR_CALL_ORDER_INVALID);  // nothing acquired
}

// Two-call idiom: a capacity of 0 is a size query, whatever the array pointer. For the
// visibility mask either capacity being 0 makes it one.
TEST_F(XrTest, CtsSizeQueriesWithZeroCapacity) {
  create_instance({XR_KHR_VISIBILITY_MASK_EXTENSION_NAME});
  create_session();
  auto get = proc<PFN_xrGetVisibilityMaskKHR>("xrGetVisibilityMaskKHR");
  XrVisibilityMaskKHR full{XR_TYPE_VISIBILITY_MASK_KHR};
  ASSERT_EQ(get(session_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR,
                &full),
            XR_SUCCESS);
  std::vector<XrVector2f> v(full.vertexCountOutput);
  std::vector<uint32_t> idx(full.indexCountOutput);
  for (int zero = 0; zero < 2; ++zero) {
    XrVisibilityMaskKHR m{XR_TYPE_VISIBILITY_MASK_KHR};
    m.vertexCapacityInput = zero == 0 ? 0 : uint32_t(v.size());
    m.vertices = zero == 0 ? nullptr : v.data();
    m.indexCapacityInput = zero == 1 ? 0 : uint32_t(idx.size());
    m.indices = zero == 1 ? nullptr : idx.data();
    EXPECT_EQ(get(session_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0,
                  XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR, &m),
              XR_SUCCESS)
        << "capacity " << (zero == 0 ? "vertex" : "index") << " 0";
    EXPECT_EQ(m.vertexCountOutput, full.vertexCountOutput);
    EXPECT_EQ(m.indexCountOutput, full.indexCountOutput);
  }
  uint32_t n = 99;
  EXPECT_EQ(xrEnumerateSwapchainFormats(session_, 0, &n, nullptr), XR_SUCCESS);
  EXPECT_GT(n, 0u);
  EXPECT_EQ(xrEnumerateReferenceSpaces(session_, 0, &n, nullptr), XR_SUCCESS);
  EXPECT_EQ(n, 3u);
  EXPECT_EQ(xrEnumerateViewConfigurations(instance_, system_, 0, &n, nullptr), XR_SUCCESS);
  EXPECT_EQ(n, 1u);
  EXPECT_EQ(xrEnumerateEnvironmentBlendModes(instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, &n,
                                             nullptr),
            XR_SUCCESS);
  EXPECT_EQ(n, 1u);
  EXPECT_EQ(xrEnumerateApiLayerProperties(0, &n, nullptr), XR_SUCCESS);
  EXPECT_EQ(xrEnumerateInstanceExtensionProperties(nullptr, 0, &n, nullptr), XR_SUCCESS);
  EXPECT_GT(n, 0u);
  EXPECT_EQ(xrPathToString(instance_, path("/user/head"), 0, &n, nullptr), XR_SUCCESS);
  EXPECT_EQ(n, 11u);  // with the terminator
  const XrSwapchain sc = color_swapchain(16, 16);
  EXPECT_EQ(xrEnumerateSwapchainImages(sc, 0, &n, nullptr), XR_SUCCESS);
  EXPECT_EQ(n, 3u);
  XrViewLocateInfo li{XR_TYPE_VIEW_LOCATE_INFO};
  li.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  li.displayTime = 1'000'000;
  li.space = reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL);
  XrViewState vs{XR_TYPE_VIEW_STATE};
  EXPECT_EQ(xrLocateViews(session_, &li, &vs, 0, &n, nullptr), XR_SUCCESS);
  EXPECT_EQ(n, 2u);
}

XrResult create_set(XrInstance instance, const char* name, const char* localized, XrActionSet* set) {
  XrActionSetCreateInfo ci{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(ci.actionSetName, name);
  std::strcpy(ci.localizedActionSetName, localized);
  return xrCreateActionSet(instance, &ci, set);
}

XrResult create_action(XrActionSet set, const char* name, const char* localized, XrActionType type,
                       XrAction* action) {
  XrActionCreateInfo ci{XR_TYPE_ACTION_CREATE_INFO};
  std::strcpy(ci.actionName, name);
  std::strcpy(ci.localizedActionName, localized);
  ci.actionType = type;
  return xrCreateAction(set, &ci, action);
}

// Empty names are XR_ERROR_NAME_INVALID; names that are not well-formed path components are
// XR_ERROR_PATH_FORMAT_INVALID; empty localized names XR_ERROR_LOCALIZED_NAME_INVALID.
TEST_F(XrTest, CtsActionNames) {
  create_instance();
  XrActionSet set = XR_NULL_HANDLE;
  EXPECT_EQ(create_set(instance_, "", "Empty", &set), XR_ERROR_NAME_INVALID);
  EXPECT_EQ(create_set(instance_, "Upper", "Upper", &set), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(create_set(instance_, "has space", "Space", &set), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(create_set(instance_, "has/slash", "Slash", &set), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(create_set(instance_, "set", "", &set), XR_ERROR_LOCALIZED_NAME_INVALID);
  ASSERT_EQ(create_set(instance_, "set-1_a.b", "Set", &set), XR_SUCCESS);
  XrAction a = XR_NULL_HANDLE;
  EXPECT_EQ(create_action(set, "", "Empty", XR_ACTION_TYPE_BOOLEAN_INPUT, &a), XR_ERROR_NAME_INVALID);
  EXPECT_EQ(create_action(set, "Bad", "Bad", XR_ACTION_TYPE_BOOLEAN_INPUT, &a), XR_ERROR_PATH_FORMAT_INVALID);
  EXPECT_EQ(create_action(set, "a", "", XR_ACTION_TYPE_BOOLEAN_INPUT, &a), XR_ERROR_LOCALIZED_NAME_INVALID);
  EXPECT_EQ(create_action(set, "a", "A", XR_ACTION_TYPE_BOOLEAN_INPUT, &a), XR_SUCCESS);
}

// Bindings are checked against the OpenXR 1.0 interaction profile tables: components a
// profile does not have (and 1.1's grip_surface) are XR_ERROR_PATH_UNSUPPORTED, every
// listed one is accepted, an identifier without its component too.
TEST_F(XrTest, CtsBindingPathsPerProfile) {
  create_instance();
  XrActionSet set = XR_NULL_HANDLE;
  ASSERT_EQ(create_set(instance_, "bindings", "Bindings", &set), XR_SUCCESS);
  XrAction pose = XR_NULL_HANDLE, button = XR_NULL_HANDLE, haptic = XR_NULL_HANDLE;
  ASSERT_EQ(create_action(set, "pose", "Pose", XR_ACTION_TYPE_POSE_INPUT, &pose), XR_SUCCESS);
  ASSERT_EQ(create_action(set, "button", "Button", XR_ACTION_TYPE_BOOLEAN_INPUT, &button), XR_SUCCESS);
  ASSERT_EQ(create_action(set, "haptic", "Haptic", XR_ACTION_TYPE_VIBRATION_OUTPUT, &haptic), XR_SUCCESS);
  const auto suggest = [&](const char* profile, XrAction action, const char* binding) {
    XrActionSuggestedBinding b{action, path(binding)};
    XrInteractionProfileSuggestedBinding s{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    s.interactionProfile = path(profile);
    s.countSuggestedBindings = 1;
    s.suggestedBindings = &b;
    return xrSuggestInteractionProfileBindings(instance_, &s);
  };
  const char* xbox = "/interaction_profiles/microsoft/xbox_controller";
  const char* touch = "/interaction_profiles/oculus/touch_controller";
  const char* simple = "/interaction_profiles/khr/simple_controller";
  EXPECT_EQ(suggest(xbox, haptic, "/user/gamepad/output/haptic_left"), XR_SUCCESS);
  EXPECT_EQ(suggest(xbox, haptic, "/user/gamepad/output/haptic_right_trigger"), XR_SUCCESS);
  EXPECT_EQ(suggest(xbox, button, "/user/gamepad/input/a/click"), XR_SUCCESS);
  EXPECT_EQ(suggest(xbox, haptic, "/user/gamepad/output/haptic"), XR_ERROR_PATH_UNSUPPORTED);
  EXPECT_EQ(suggest(xbox, button, "/user/gamepad/input/z/click"), XR_ERROR_PATH_UNSUPPORTED);
  EXPECT_EQ(suggest(simple, pose, "/user/hand/left/input/grip/pose"), XR_SUCCESS);
  EXPECT_EQ(suggest(simple, pose, "/user/hand/left/input/grip_surface/pose"), XR_ERROR_PATH_UNSUPPORTED);
  EXPECT_EQ(suggest(simple, button, "/user/hand/left/input/trigger/click"), XR_ERROR_PATH_UNSUPPORTED);
  EXPECT_EQ(suggest(simple, button, "/user/hand/right/input/select"), XR_SUCCESS);  // identifier only
  EXPECT_EQ(suggest(simple, button, "/user/hand/right/input/select/value"), XR_ERROR_PATH_UNSUPPORTED);
  EXPECT_EQ(suggest(simple, button, "/user/hand/left/input"), XR_ERROR_PATH_UNSUPPORTED);
  EXPECT_EQ(suggest(simple, haptic, "/user/hand/right/output/haptic"), XR_SUCCESS);
  // Oculus Touch: X/Y on the left controller, A/B on the right.
  EXPECT_EQ(suggest(touch, button, "/user/hand/left/input/x/click"), XR_SUCCESS);
  EXPECT_EQ(suggest(touch, button, "/user/hand/right/input/x/click"), XR_ERROR_PATH_UNSUPPORTED);
  EXPECT_EQ(suggest(touch, button, "/user/hand/right/input/a/touch"), XR_SUCCESS);
  EXPECT_EQ(suggest(touch, button, "/user/hand/left/input/system/click"), XR_ERROR_PATH_UNSUPPORTED);
  EXPECT_EQ(suggest("/interaction_profiles/htc/vive_pro", button, "/user/head/input/volume_up/click"), XR_SUCCESS);
  EXPECT_EQ(suggest("/interaction_profiles/htc/vive_pro", button, "/user/head/input/trigger/click"),
            XR_ERROR_PATH_UNSUPPORTED);
  EXPECT_EQ(suggest("/interaction_profiles/valve/index_controller", button, "/user/hand/left/input/trackpad/force"),
            XR_SUCCESS);
  EXPECT_EQ(suggest("/interaction_profiles/google/daydream_controller", haptic, "/user/hand/left/output/haptic"),
            XR_ERROR_PATH_UNSUPPORTED);
}

// XR_FORM_FACTOR_MAX_ENUM and unknown reference space types: the *_UNSUPPORTED codes the
// CTS expects.
TEST_F(XrTest, CtsUnsupportedEnums) {
  create_instance();
  XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
  gi.formFactor = XR_FORM_FACTOR_MAX_ENUM;
  XrSystemId id = 0;
  EXPECT_EQ(xrGetSystem(instance_, &gi, &id), XR_ERROR_FORM_FACTOR_UNSUPPORTED);
  create_session();
  XrReferenceSpaceCreateInfo rci{XR_TYPE_REFERENCE_SPACE_CREATE_INFO};
  rci.poseInReferenceSpace.orientation.w = 1;
  XrSpace space = XR_NULL_HANDLE;
  for (auto t : {XR_REFERENCE_SPACE_TYPE_MAX_ENUM, XrReferenceSpaceType(12345)}) {
    rci.referenceSpaceType = t;
    EXPECT_EQ(xrCreateReferenceSpace(session_, &rci, &space), XR_ERROR_REFERENCE_SPACE_UNSUPPORTED) << t;
    XrExtent2Df bounds;
    EXPECT_EQ(xrGetReferenceSpaceBoundsRect(session_, t, &bounds), XR_ERROR_REFERENCE_SPACE_UNSUPPORTED) << t;
  }
}

// Actions are inactive while the session is not focused: the eye gaze action reports
// inactive and its space untracked before FOCUSED and again after focus is lost.
// CTS 1.1.41 `multithreading`: "Event with type XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED
// must only be queued during xrSyncActions". The runtime used to queue it inside
// xrAttachSessionActionSets, session not even running. Now the eye-gaze profile becomes
// current, and its event is queued, at the first xrSyncActions of a running session.
TEST_F(XrTest, CtsInteractionProfileChangedOnlyDuringSyncActions) {
  create_instance({XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME});
  create_session();
  XrActionSet set = XR_NULL_HANDLE;
  attach_gaze_action(instance_, session_, &set);
  const XrPath eyes = path("/user/eyes_ext"), profile = path("/interaction_profiles/ext/eye_gaze_interaction");
  // The event types polled now, and the eye-gaze profile current now.
  const auto events = [&] {
    std::vector<XrStructureType> types;
    for (XrEventDataBuffer ev{XR_TYPE_EVENT_DATA_BUFFER}; xrPollEvent(instance_, &ev) == XR_SUCCESS;
         ev = {XR_TYPE_EVENT_DATA_BUFFER}) {
      types.push_back(ev.type);
      if (ev.type == XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED) {
        EXPECT_EQ(reinterpret_cast<XrEventDataInteractionProfileChanged*>(&ev)->session, session_);
      }
    }
    return std::count(types.begin(), types.end(), XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED);
  };
  const auto current = [&] {
    XrInteractionProfileState ips{XR_TYPE_INTERACTION_PROFILE_STATE};
    EXPECT_EQ(xrGetCurrentInteractionProfile(session_, eyes, &ips), XR_SUCCESS);
    return ips.interactionProfile;
  };
  EXPECT_EQ(events(), 0) << "after the attach (IDLE, READY)";
  EXPECT_EQ(current(), XrPath(XR_NULL_PATH));
  XrActiveActionSet active{set, XR_NULL_PATH};
  XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  EXPECT_EQ(xrSyncActions(session_, &sync), XR_SESSION_NOT_FOCUSED);
  EXPECT_EQ(events(), 0) << "after a sync before xrBeginSession";
  EXPECT_EQ(current(), XrPath(XR_NULL_PATH));
  XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  ASSERT_EQ(xrBeginSession(session_, &bi), XR_SUCCESS);
  ASSERT_EQ(frame(), XR_SUCCESS);
  EXPECT_EQ(events(), 0) << "running, before a sync (SYNCHRONIZED, VISIBLE, FOCUSED)";
  EXPECT_EQ(current(), XrPath(XR_NULL_PATH));
  EXPECT_EQ(xrSyncActions(session_, &sync), XR_SUCCESS);
  EXPECT_EQ(events(), 1) << "after the first sync of the running session";
  EXPECT_EQ(current(), profile);
  EXPECT_EQ(xrSyncActions(session_, &sync), XR_SUCCESS);
  EXPECT_EQ(events(), 0) << "the profile did not change again";
}

TEST_F(XrTest, CtsEyeGazeInactiveWhenNotFocused) {
  create_instance({XR_EXT_EYE_GAZE_INTERACTION_EXTENSION_NAME});
  create_session();
  XrActionSet set = XR_NULL_HANDLE;
  const XrAction gaze = attach_gaze_action(instance_, session_, &set);
  XrActionSpaceCreateInfo sci{XR_TYPE_ACTION_SPACE_CREATE_INFO};
  sci.action = gaze;
  sci.poseInActionSpace.orientation.w = 1;
  XrSpace gaze_space = XR_NULL_HANDLE;
  ASSERT_EQ(xrCreateActionSpace(session_, &sci, &gaze_space), XR_SUCCESS);
  const XrSpace view = reference_space(XR_REFERENCE_SPACE_TYPE_VIEW);
  XrActiveActionSet active{set, XR_NULL_PATH};
  XrActionsSyncInfo sync{XR_TYPE_ACTIONS_SYNC_INFO};
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  XrActionStateGetInfo gsi{XR_TYPE_ACTION_STATE_GET_INFO};
  gsi.action = gaze;
  const auto check = [&](bool focused, const char* when) {
    EXPECT_EQ(xrSyncActions(session_, &sync), focused ? XR_SUCCESS : XR_SESSION_NOT_FOCUSED) << when;
    XrActionStatePose st{XR_TYPE_ACTION_STATE_POSE};
    ASSERT_EQ(xrGetActionStatePose(session_, &gsi, &st), XR_SUCCESS) << when;
    EXPECT_EQ(bool(st.isActive), focused) << when;
    // Over a second of tracker samples (a blink is never that long; the runtime reads the
    // samples delivered by now, so focused, frames pass between the reads) at least one is
    // tracked when focused, none when not.
    int tracked = 0;
    for (int i = 0; i < 70; ++i) {
      XrFrameState fs{XR_TYPE_FRAME_STATE};
      if (focused) {
        ASSERT_EQ(frame({}, &fs), XR_SUCCESS);
      }
      XrSpaceLocation loc{XR_TYPE_SPACE_LOCATION};
      ASSERT_EQ(xrLocateSpace(gaze_space, view, focused ? fs.predictedDisplayTime : mono_now(), &loc), XR_SUCCESS);
      tracked += (loc.locationFlags & XR_SPACE_LOCATION_ORIENTATION_TRACKED_BIT) != 0;
    }
    EXPECT_EQ(tracked > 0, focused) << when << ": " << tracked;
  };
  check(false, "IDLE/READY");
  poll_states();
  XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  ASSERT_EQ(xrBeginSession(session_, &bi), XR_SUCCESS);
  ASSERT_EQ(frame(), XR_SUCCESS);
  poll_states();
  check(true, "FOCUSED");
  ASSERT_EQ(xrRequestExitSession(session_), XR_SUCCESS);
  poll_states();  // VISIBLE, SYNCHRONIZED, STOPPING
  check(false, "STOPPING");
}

// The timing log carries the host time of xrEndFrame's stages under "cpu_ms": on a frame
// whose panels are produced, the lens and PNG writing took time, nothing was read back
// without layers, and the stages fit in the compositor's total.
TEST_F(XrTest, TimingLogCpuStages) {
  TempDir dir("cpu_ms");
  setenv("FOVEA_RUNTIME_OUT", dir.path().c_str(), 1);
  setenv("FOVEA_RUNTIME_PNG_EVERY", "1", 1);
  create_instance();
  run_to_focused();
  ASSERT_EQ(frame(), XR_SUCCESS);
  unsetenv("FOVEA_RUNTIME_PNG_EVERY");
  unsetenv("FOVEA_RUNTIME_OUT");
  std::ifstream in(dir.path() + "/timing.jsonl");
  int composited = 0;
  for (std::string line; std::getline(in, line);) {
    const auto cpu = line.find("\"cpu_ms\":{");
    ASSERT_NE(cpu, std::string::npos) << line;
    const auto field = [&](const char* name, std::size_t from) {
      const auto at = line.find(std::string("\"") + name + "\":", from);
      EXPECT_NE(at, std::string::npos) << name << " in " << line;
      return at == std::string::npos ? -1.0 : std::stod(line.substr(at + std::strlen(name) + 3));
    };
    double sum = 0;
    for (const char* stage : {"validate", "gaze", "readback", "resample", "lens", "write"}) {
      const double ms = field(stage, cpu);
      EXPECT_GE(ms, 0.0) << stage;
      if (std::string(stage) != "validate" && std::string(stage) != "gaze") sum += ms;
    }
    if (line.find("\"composited\":true") == std::string::npos) continue;
    ++composited;
    if (field("layers", 0) == 0) {
      EXPECT_EQ(field("readback", cpu), 0.0) << line;
    }
    EXPECT_GT(field("lens", cpu), 0.0) << line;
    EXPECT_GT(field("write", cpu), 0.0) << line;
    EXPECT_LE(sum, field("compositor_ms", 0) + 0.01) << line;  // %.3f rounding of five numbers
  }
  EXPECT_GE(composited, 1);
}

// A missing FOVEA_RUNTIME_OUT directory is created (with its parents): the first frame
// succeeds and the timing log and runtime log are written. A path that cannot be a
// directory fails instance creation with the variable named, not a frame.
TEST_F(XrTest, RuntimeOutDirectoryCreated) {
  TempDir dir("out_missing");
  const std::string out = dir.path() + "/not/yet/there";
  setenv("FOVEA_RUNTIME_OUT", out.c_str(), 1);
  setenv("FOVEA_RUNTIME_PNG_EVERY", "1", 1);
  create_instance();
  run_to_focused();
  ASSERT_EQ(frame(), XR_SUCCESS);
  unsetenv("FOVEA_RUNTIME_PNG_EVERY");
  unsetenv("FOVEA_RUNTIME_OUT");
  std::ifstream in(out + "/timing.jsonl");
  int lines = 0;
  for (std::string l; std::getline(in, l);) ++lines;
  EXPECT_EQ(lines, 2);
  EXPECT_TRUE(std::filesystem::exists(out + "/runtime.log"));
  ASSERT_EQ(xrDestroyInstance(instance_), XR_SUCCESS);  // one instance at a time
  instance_ = XR_NULL_HANDLE;
  session_ = XR_NULL_HANDLE;

  const std::string file = dir.path() + "/a_file";
  std::ofstream(file) << "x";
  setenv("FOVEA_RUNTIME_OUT", (file + "/sub").c_str(), 1);
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "fovea_runtime_tests");
  ci.applicationInfo.apiVersion = XR_CURRENT_API_VERSION;
  XrInstance inst = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateInstance(&ci, &inst), XR_ERROR_INITIALIZATION_FAILED);
  unsetenv("FOVEA_RUNTIME_OUT");
}

// Honest pacing (realtime, the default), with a real slow frame and invariants only (a
// loaded host may deschedule the test at any point): the predicted display time is never
// in the past — after the call, and in the runtime's record when it returned — even after a
// frame five periods late; xrWaitFrame throttles again afterwards (it never returns before
// the frame's wake time, one period plus the compositor budget before its display time);
// every frame's display time is on the vsync grid and later than the previous one; the
// timing log never shows a frame displayed before it was submitted.
TEST_F(XrTest, PacingNeverPredictsThePast) {
  TempDir dir("pacing");
  setenv("FOVEA_RUNTIME_OUT", dir.path().c_str(), 1);
  setenv("FOVEA_RUNTIME_PNG_EVERY", "1000000", 1);
  create_instance();
  unsetenv("FOVEA_RUNTIME_OUT");
  unsetenv("FOVEA_RUNTIME_PNG_EVERY");
  run_to_focused();
  XrFrameState first{XR_TYPE_FRAME_STATE};
  ASSERT_EQ(frame({}, &first), XR_SUCCESS);
  const XrDuration period = first.predictedDisplayPeriod;
  const XrDuration budget = std::max<XrDuration>(period / 5, 3'000'000);
  XrTime last = first.predictedDisplayTime;
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  for (int i = 0; i < 8; ++i) {
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    const XrTime called = mono_now();
    ASSERT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_SUCCESS);
    const XrTime returned = mono_now();
    EXPECT_GT(fs.predictedDisplayTime, called) << "frame " << i;
    EXPECT_GE(returned, fs.predictedDisplayTime - period - budget) << "frame " << i << ": not throttled";
    EXPECT_GT(fs.predictedDisplayTime, last);
    EXPECT_EQ((fs.predictedDisplayTime - first.predictedDisplayTime) % period, 0);
    last = fs.predictedDisplayTime;
    ASSERT_EQ(xrBeginFrame(session_, nullptr), XR_SUCCESS);
    if (i == 2) {  // a slow frame: five periods of work
      const timespec slow{0, long(5 * period)};
      nanosleep(&slow, nullptr);
    }
    ei.displayTime = fs.predictedDisplayTime;
    ASSERT_EQ(xrEndFrame(session_, &ei), XR_SUCCESS);
  }
  ASSERT_EQ(xrDestroySession(session_), XR_SUCCESS);  // flushes nothing: records are flushed per frame
  session_ = XR_NULL_HANDLE;
  std::ifstream in(dir.path() + "/timing.jsonl");
  int records = 0, missed = 0;
  for (std::string line; std::getline(in, line); ++records) {
    const auto field = [&](const char* name) {
      const auto at = line.find(std::string("\"") + name + "\":");
      EXPECT_NE(at, std::string::npos) << name;
      return std::stoll(line.substr(at + std::strlen(name) + 3));
    };
    EXPECT_GE(field("vsync_ns"), field("end_call_ns")) << line;
    EXPECT_GE(field("vsync_ns"), field("predicted_display_ns")) << line;
    EXPECT_GT(field("predicted_display_ns"), field("wait_return_ns")) << line;
    missed += int(field("missed_vsyncs"));
  }
  EXPECT_EQ(records, 10);
  EXPECT_GE(missed, 4);  // the slow frame cost at least four vsyncs
}

// Copies `image` (64×72 RGBA8, COLOR_ATTACHMENT_OPTIMAL) to a host buffer on the test's
// device and back to its layout, as an API layer reading the application's images does.
void copy_image_out(VkPhysicalDevice physical, VkDevice device, uint32_t family, VkImage image) {
  VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bi.size = 64 * 72 * 4;
  bi.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateBuffer(device, &bi, nullptr, &buffer), VK_SUCCESS);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device, buffer, &req);
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical, &mp);
  VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((req.memoryTypeBits & (1u << i)) && (mp.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)) {
      ai.memoryTypeIndex = i;
      break;
    }
  VkDeviceMemory memory = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateMemory(device, &ai, nullptr, &memory), VK_SUCCESS);
  ASSERT_EQ(vkBindBufferMemory(device, buffer, memory, 0), VK_SUCCESS);
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.queueFamilyIndex = family;
  VkCommandPool pool = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateCommandPool(device, &pci, nullptr, &pool), VK_SUCCESS);
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateCommandBuffers(device, &cai, &cmd), VK_SUCCESS);
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkBeginCommandBuffer(cmd, &begin);
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  b.oldLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &b);
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {64, 72, 1};
  vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer, 1, &region);
  std::swap(b.oldLayout, b.newLayout);
  b.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  b.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &b);
  vkEndCommandBuffer(cmd);
  VkQueue queue = VK_NULL_HANDLE;
  vkGetDeviceQueue(device, family, 0, &queue);
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  EXPECT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
  vkQueueWaitIdle(queue);
  vkDestroyCommandPool(device, pool, nullptr);
  vkDestroyBuffer(device, buffer, nullptr);
  vkFreeMemory(device, memory, nullptr);
}

// Swapchain images carry the usage the application asked for (plus the sampling the
// compositor needs), never an unrequested transfer source: copying from an image of a
// swapchain created without XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT is reported by the Vulkan
// validation layer, as it would be on other runtimes, and from one created with it is not.
// The compositor itself reads an attachment-only swapchain cleanly (by sampling).
TEST_F(XrTest, SwapchainUsageIsWhatWasAsked) {
  const char* v = std::getenv("FOVEA_VK_VALIDATION");
  if (!v || std::string(v) != "1") GTEST_SKIP() << "needs FOVEA_VK_VALIDATION=1 (the validation layer observes the usage)";
  TempDir dir("usage");
  setenv("FOVEA_RUNTIME_OUT", dir.path().c_str(), 1);
  create_instance();
  unsetenv("FOVEA_RUNTIME_OUT");
  run_to_focused();
  const auto make = [&](XrSwapchainUsageFlags usage) {
    const XrSwapchain sc = color_swapchain(64, 72, usage);
    uint32_t n = 3, i = 0;
    std::vector<XrSwapchainImageVulkan2KHR> images(n, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN2_KHR});
    EXPECT_EQ(xrEnumerateSwapchainImages(sc, n, &n, reinterpret_cast<XrSwapchainImageBaseHeader*>(images.data())),
              XR_SUCCESS);
    EXPECT_EQ(xrAcquireSwapchainImage(sc, nullptr, &i), XR_SUCCESS);
    XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
    wi.timeout = XR_INFINITE_DURATION;
    EXPECT_EQ(xrWaitSwapchainImage(sc, &wi), XR_SUCCESS);
    return std::pair{sc, images[i].image};
  };
  const auto copyable = make(XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT);
  const auto attachment = make(XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT);
  copy_image_out(vk_physical_, vk_device_, queue_family_, copyable.second);
  EXPECT_EQ(validation_errors_, 0) << "copy from a swapchain created with the transfer-source usage";
  expect_validation_errors(true);
  copy_image_out(vk_physical_, vk_device_, queue_family_, attachment.second);
  expect_validation_errors(false);
  EXPECT_GT(validation_errors_, 0) << "copy from a swapchain created without it";
  validation_errors_ = 0;
  for (auto sc : {copyable.first, attachment.first}) ASSERT_EQ(xrReleaseSwapchainImage(sc, nullptr), XR_SUCCESS);
  const StereoLayer stereo(attachment.first, reference_space(XR_REFERENCE_SPACE_TYPE_LOCAL));
  ASSERT_EQ(frame({stereo.header()}), XR_SUCCESS);
  EXPECT_TRUE(std::filesystem::exists(dir.path() + "/panel_000001_left.png"));
  // TearDown: no validation message from the compositor's read.
}

TEST_F(XrTest, TimespecConversion) {
  create_instance({XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME});
  auto to_time = proc<PFN_xrConvertTimespecTimeToTimeKHR>("xrConvertTimespecTimeToTimeKHR");
  auto to_ts = proc<PFN_xrConvertTimeToTimespecTimeKHR>("xrConvertTimeToTimespecTimeKHR");
  timespec ts{12, 345};
  XrTime t = 0;
  ASSERT_EQ(to_time(instance_, &ts, &t), XR_SUCCESS);
  EXPECT_EQ(t, 12'000'000'345);
  timespec back{};
  ASSERT_EQ(to_ts(instance_, t, &back), XR_SUCCESS);
  EXPECT_EQ(back.tv_sec, 12);
  EXPECT_EQ(back.tv_nsec, 345);
  EXPECT_EQ(to_ts(instance_, 0, &back), XR_ERROR_TIME_INVALID);
}

// Control for the hello_xr core-validation test: misuse through the Khronos core validation
// layer is written to its report as a VUID, which is what that test looks for.
TEST_F(XrTest, CoreValidationReportsMisuse) {
  TempDir dir("cv_control");
  const std::string report = dir.path() + "/core_validation.txt";
  setenv("XR_ENABLE_API_LAYERS", "XR_APILAYER_LUNARG_core_validation", 1);
  setenv("XR_CORE_VALIDATION_EXPORT_TYPE", "text", 1);
  setenv("XR_CORE_VALIDATION_FILE_NAME", report.c_str(), 1);
  create_instance();
  XrInstanceProperties props{XR_TYPE_SYSTEM_PROPERTIES};  // wrong structure type
  EXPECT_EQ(xrGetInstanceProperties(instance_, &props), XR_ERROR_VALIDATION_FAILURE);
  ASSERT_EQ(xrDestroyInstance(instance_), XR_SUCCESS);  // flushes the report
  instance_ = XR_NULL_HANDLE;
  unsetenv("XR_ENABLE_API_LAYERS");
  unsetenv("XR_CORE_VALIDATION_EXPORT_TYPE");
  unsetenv("XR_CORE_VALIDATION_FILE_NAME");
  EXPECT_NE(read_text(report).find("VUID-XrInstanceProperties-type-type"), std::string::npos) << read_text(report);
}

TEST_F(XrTest, UnsupportedExtensionRejected) {
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "fovea_runtime_tests");
  ci.applicationInfo.apiVersion = XR_CURRENT_API_VERSION;
  const char* ext = "XR_MSFT_hand_interaction";
  ci.enabledExtensionCount = 1;
  ci.enabledExtensionNames = &ext;
  XrInstance inst = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateInstance(&ci, &inst), XR_ERROR_EXTENSION_NOT_PRESENT);
}

TEST_F(XrTest, BadConfigurationFailsInitialization) {
  setenv("FOVEA_DISPLAY", "no-such-display", 1);
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "fovea_runtime_tests");
  ci.applicationInfo.apiVersion = XR_CURRENT_API_VERSION;
  XrInstance inst = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateInstance(&ci, &inst), XR_ERROR_INITIALIZATION_FAILED);
  setenv("FOVEA_DISPLAY", "tiny", 1);
  setenv("FOVEA_GAZE", "nonsense:1", 1);
  EXPECT_EQ(xrCreateInstance(&ci, &inst), XR_ERROR_INITIALIZATION_FAILED);
  unsetenv("FOVEA_GAZE");
}

}  // namespace
}  // namespace fovea::test
