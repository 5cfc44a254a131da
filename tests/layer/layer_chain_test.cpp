// The layer library on a fake next layer (in place of the runtime) that records every call
// the layer makes down the chain and can fail the Nth call of a command: teardown order,
// cleanup after partial failure, and reported (not fatal) output failures.
#include <dlfcn.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#define XR_USE_TIMESPEC  // xrConvertTimeToTimespecTimeKHR
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include "fovea/xrcommon/loader_interface.hpp"

namespace {

// Set before the layer first logs (its log file is opened once per process).
const bool kLogFileSet = [] {
  // Under a file, so that no directory can be created there (not even by root).
  setenv("FOVEA_LAYER_LOG_FILE", "/dev/null/fovea/layer.log", 1);
  setenv("FOVEA_LAYER_LOG_LEVEL", "info", 1);
  return true;
}();

constexpr const char* kLayerName = "XR_APILAYER_FOVEA_path_tracing";
constexpr XrTime kXrTimeAhead = 1'000'000'000;

// The fake next layer's state: the calls in order ("command handle"), failures to inject.
struct Fake {
  std::vector<std::string> calls;
  std::map<std::string, int> count;
  std::map<std::string, int> fail_at;  // command -> the call (1-based) that fails
  std::uint64_t next_handle = 0x1000;
  bool eye_gaze = true;
  bool visibility_mask = false;         // the fake offers XR_KHR_visibility_mask
  bool convert_timespec = false;        // the fake offers XR_KHR_convert_timespec_time
  std::vector<std::string> enabled;     // the extensions enabled on the call down
  int mask_events = 0;                  // visibility-mask change events queued for xrPollEvent
} g;

// Records a call; true when it is the one to fail.
bool record(const char* name, std::uint64_t handle) {
  g.calls.push_back(std::string(name) + " " + std::to_string(handle));
  const int n = ++g.count[name];
  const auto f = g.fail_at.find(name);
  return f != g.fail_at.end() && f->second == n;
}

template <class H>
std::uint64_t id(H h) {
  return reinterpret_cast<std::uint64_t>(h);
}

template <class H>
XrResult create(const char* name, std::uint64_t parent, H* out) {
  if (record(name, parent)) return XR_ERROR_RUNTIME_FAILURE;
  *out = reinterpret_cast<H>(g.next_handle++);
  g.calls.back() += " -> " + std::to_string(id(*out));
  return XR_SUCCESS;
}

XrResult XRAPI_CALL fake_enumerate_extensions(const char*, uint32_t capacity, uint32_t* count, XrExtensionProperties* p) {
  std::vector<const char*> names;
  if (g.eye_gaze) names.push_back("XR_EXT_eye_gaze_interaction");
  if (g.visibility_mask) names.push_back("XR_KHR_visibility_mask");
  if (g.convert_timespec) names.push_back("XR_KHR_convert_timespec_time");
  *count = uint32_t(names.size());
  if (capacity < names.size()) return capacity ? XR_ERROR_SIZE_INSUFFICIENT : XR_SUCCESS;
  for (std::size_t i = 0; i < names.size(); ++i) std::strcpy(p[i].extensionName, names[i]);
  return XR_SUCCESS;
}

// Delivers the queued visibility-mask change events, then none.
XrResult XRAPI_CALL fake_poll_event(XrInstance instance, XrEventDataBuffer* event) {
  record("xrPollEvent", id(instance));
  if (g.mask_events == 0) return XR_EVENT_UNAVAILABLE;
  --g.mask_events;
  auto* e = reinterpret_cast<XrEventDataVisibilityMaskChangedKHR*>(event);
  *e = {XR_TYPE_EVENT_DATA_VISIBILITY_MASK_CHANGED_KHR};
  e->viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  return XR_SUCCESS;
}

XrResult XRAPI_CALL fake_gipa(XrInstance instance, const char* name, PFN_xrVoidFunction* fn);

XrResult XRAPI_CALL fake_create_instance(const XrInstanceCreateInfo* info, const XrApiLayerCreateInfo*, XrInstance* out) {
  g.enabled.assign(info->enabledExtensionNames, info->enabledExtensionNames + info->enabledExtensionCount);
  return create("xrCreateInstance", 0, out);
}

#define FAKE(name, ...)                                           \
  if (!std::strcmp(n, #name)) {                                   \
    PFN_##name p = __VA_ARGS__;                                   \
    *fn = reinterpret_cast<PFN_xrVoidFunction>(p);                \
    return XR_SUCCESS;                                            \
  }
// A command that only succeeds or fails; its first argument is the handle it acts on.
#define FAKE_PLAIN(name) \
  FAKE(name, [](auto h, auto...) -> XrResult { return record(#name, id(h)) ? XR_ERROR_RUNTIME_FAILURE : XR_SUCCESS; })
#define FAKE_CREATE(name) \
  FAKE(name, [](auto parent, auto, auto* out) -> XrResult { return create(#name, id(parent), out); })

XrResult XRAPI_CALL fake_gipa(XrInstance, const char* n, PFN_xrVoidFunction* fn) {
  FAKE(xrGetInstanceProcAddr, &fake_gipa)
  FAKE(xrEnumerateInstanceExtensionProperties, &fake_enumerate_extensions)
  FAKE_CREATE(xrCreateSession)
  FAKE_CREATE(xrCreateSwapchain)
  FAKE_CREATE(xrCreateActionSet)
  FAKE_CREATE(xrCreateAction)
  FAKE_CREATE(xrStringToPath)
  FAKE_CREATE(xrCreateActionSpace)
  FAKE_CREATE(xrCreateReferenceSpace)
  FAKE_PLAIN(xrDestroyInstance)
  FAKE_PLAIN(xrDestroySession)
  FAKE_PLAIN(xrDestroySwapchain)
  FAKE_PLAIN(xrDestroyActionSet)
  FAKE_PLAIN(xrDestroyAction)
  FAKE_PLAIN(xrDestroySpace)
  FAKE_PLAIN(xrEnumerateSwapchainImages)
  FAKE_PLAIN(xrAcquireSwapchainImage)
  FAKE_PLAIN(xrWaitSwapchainImage)
  FAKE_PLAIN(xrReleaseSwapchainImage)
  FAKE_PLAIN(xrWaitFrame)
  FAKE_PLAIN(xrBeginFrame)
  FAKE_PLAIN(xrEndFrame)
  FAKE_PLAIN(xrSuggestInteractionProfileBindings)
  FAKE_PLAIN(xrAttachSessionActionSets)
  FAKE_PLAIN(xrSyncActions)
  FAKE_PLAIN(xrLocateSpace)
  FAKE_PLAIN(xrGetSystemProperties)
  FAKE_PLAIN(xrGetCurrentInteractionProfile)
  FAKE(xrPollEvent, &fake_poll_event)
  if (g.visibility_mask) FAKE_PLAIN(xrGetVisibilityMaskKHR)
  // The fake's XrTime runs kXrTimeAhead ahead of CLOCK_MONOTONIC (as another runtime's may).
  if (g.convert_timespec)
    FAKE(xrConvertTimeToTimespecTimeKHR, [](XrInstance h, XrTime t, timespec* ts) -> XrResult {
      record("xrConvertTimeToTimespecTimeKHR", id(h));
      const XrTime m = t - kXrTimeAhead;
      *ts = {time_t(m / 1'000'000'000), long(m % 1'000'000'000)};
      return XR_SUCCESS;
    })
  *fn = nullptr;
  return XR_ERROR_FUNCTION_UNSUPPORTED;
}

// The layer library, negotiated as the loader would.
struct LayerLib {
  void* lib = nullptr;
  XrNegotiateApiLayerRequest request{};
  LayerLib() {
    lib = dlopen(FOVEA_LAYER_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (!lib) return;
    auto negotiate = reinterpret_cast<PFN_xrNegotiateLoaderApiLayerInterface>(
        dlsym(lib, "xrNegotiateLoaderApiLayerInterface"));
    XrNegotiateLoaderInfo info{XR_LOADER_INTERFACE_STRUCT_LOADER_INFO, XR_LOADER_INFO_STRUCT_VERSION,
                               sizeof(XrNegotiateLoaderInfo), 1, 1, XR_MAKE_VERSION(1, 0, 0), XR_CURRENT_API_VERSION};
    request = {XR_LOADER_INTERFACE_STRUCT_API_LAYER_REQUEST, XR_API_LAYER_INFO_STRUCT_VERSION,
               sizeof(XrNegotiateApiLayerRequest), 0, 0, nullptr, nullptr};
    if (!negotiate || XR_FAILED(negotiate(&info, kLayerName, &request))) request.getInstanceProcAddr = nullptr;
  }
  ~LayerLib() {
    if (lib) dlclose(lib);
  }

  XrInstance create_instance(std::vector<const char*> extensions = {}) {
    XrApiLayerNextInfo next{XR_LOADER_INTERFACE_STRUCT_API_LAYER_NEXT_INFO, XR_API_LAYER_NEXT_INFO_STRUCT_VERSION,
                            sizeof(XrApiLayerNextInfo), {}, &fake_gipa, &fake_create_instance, nullptr};
    std::strcpy(next.layerName, kLayerName);
    XrApiLayerCreateInfo layer_info{XR_LOADER_INTERFACE_STRUCT_API_LAYER_CREATE_INFO,
                                    XR_API_LAYER_CREATE_INFO_STRUCT_VERSION, sizeof(XrApiLayerCreateInfo), nullptr,
                                    {}, &next};
    XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
    std::strcpy(ci.applicationInfo.applicationName, "fovea_layer_chain_test");
    ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
    ci.enabledExtensionCount = uint32_t(extensions.size());
    ci.enabledExtensionNames = extensions.data();
    XrInstance instance = XR_NULL_HANDLE;
    EXPECT_EQ(request.createApiLayerInstance(&ci, &layer_info, &instance), XR_SUCCESS);
    return instance;
  }

  template <class PFN>
  PFN get(XrInstance instance, const char* name) {
    PFN_xrVoidFunction fn = nullptr;
    EXPECT_EQ(request.getInstanceProcAddr(instance, name, &fn), XR_SUCCESS) << name;
    return reinterpret_cast<PFN>(fn);
  }
};

class LayerChain : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(kLogFileSet);
    g = Fake{};
    // No configuration file; a scene makes the layer set up its eye-gaze input.
    setenv("XDG_CONFIG_HOME", "/nonexistent-fovea-config", 1);
    setenv("FOVEA_SCENE", "cornell", 1);
    unsetenv("FOVEA_LAYER_SCENE");
    unsetenv("FOVEA_LAYER_OUT");
    ASSERT_NE(layer_.lib, nullptr) << dlerror();
    ASSERT_NE(layer_.request.getInstanceProcAddr, nullptr);
  }
  void TearDown() override { unsetenv("FOVEA_SCENE"); }

  // Index of the first recorded call starting with `prefix` (calls.size() when none).
  static std::size_t find(const std::string& prefix) {
    return std::size_t(std::find_if(g.calls.begin(), g.calls.end(),
                                    [&](const std::string& c) { return c.rfind(prefix, 0) == 0; }) -
                       g.calls.begin());
  }
  static std::uint64_t created(const char* command) {
    const std::string& c = g.calls.at(find(command));
    return std::stoull(c.substr(c.find("-> ") + 3));
  }

  LayerLib layer_;
};

// First: the log file is opened at the process's first log line. An unwritable log file or output directory is reported and the layer keeps working.
TEST_F(LayerChain, OutputFailuresAreReportedNotFatal) {
  unsetenv("FOVEA_SCENE");
  setenv("FOVEA_LAYER_OUT", "/dev/null/fovea/out", 1);  // missing directories are created, not under a file
  testing::internal::CaptureStderr();
  const XrInstance instance = layer_.create_instance();
  XrSessionCreateInfo si{XR_TYPE_SESSION_CREATE_INFO};
  XrSession session = XR_NULL_HANDLE;
  const XrResult r = layer_.get<PFN_xrCreateSession>(instance, "xrCreateSession")(instance, &si, &session);
  const XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
  const XrResult e = layer_.get<PFN_xrEndFrame>(instance, "xrEndFrame")(session, &end);
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(r, XR_SUCCESS);
  EXPECT_EQ(e, XR_SUCCESS);
  EXPECT_EQ(find("xrEndFrame"), g.calls.size() - 1);  // the frame went down
  EXPECT_NE(err.find("FOVEA_LAYER_LOG_FILE \"/dev/null/fovea/layer.log\""), std::string::npos) << err;
  EXPECT_NE(err.find("FOVEA_LAYER_OUT=/dev/null/fovea/out: cannot create the directory"), std::string::npos) << err;
  ASSERT_EQ(layer_.get<PFN_xrDestroyInstance>(instance, "xrDestroyInstance")(instance), XR_SUCCESS);
}

TEST_F(LayerChain, DestroyInstanceReleasesTheLayersObjectsBeforeCallingDown) {
  const XrInstance instance = layer_.create_instance();
  const std::uint64_t set = created("xrCreateActionSet");
  auto destroy = layer_.get<PFN_xrDestroyInstance>(instance, "xrDestroyInstance");
  ASSERT_EQ(destroy(instance), XR_SUCCESS);
  const std::size_t destroy_set = find("xrDestroyActionSet " + std::to_string(set));
  const std::size_t destroy_instance = find("xrDestroyInstance");
  ASSERT_LT(destroy_set, g.calls.size()) << "the layer's action set was never destroyed";
  EXPECT_LT(destroy_set, destroy_instance);
  EXPECT_EQ(destroy_instance, g.calls.size() - 1);  // nothing on dead handles afterwards
}

// Each creation step of the eye-gaze input failing in turn: the instance still works and
// nothing the layer created is left behind.
TEST_F(LayerChain, EyeGazeSetupFailureLeavesNothingBehind) {
  for (const char* step : {"xrCreateAction", "xrStringToPath", "xrSuggestInteractionProfileBindings"}) {
    SCOPED_TRACE(step);
    g = Fake{};
    g.fail_at[step] = 1;
    const XrInstance instance = layer_.create_instance();
    ASSERT_NE(instance, XR_NULL_HANDLE);
    const std::uint64_t set = created("xrCreateActionSet");
    const std::size_t destroyed = find("xrDestroyActionSet " + std::to_string(set));
    ASSERT_LT(destroyed, g.calls.size()) << "the action set leaked";
    EXPECT_LT(find(step), destroyed);
    g.calls.clear();
    ASSERT_EQ(layer_.get<PFN_xrDestroyInstance>(instance, "xrDestroyInstance")(instance), XR_SUCCESS);
    EXPECT_EQ(g.calls, std::vector<std::string>{"xrDestroyInstance " + std::to_string(id(instance))});
  }
}

// Without a scene the layer creates nothing of its own: only the application's call goes down.
TEST_F(LayerChain, PassThroughDestroyInstanceOnlyCallsDown) {
  unsetenv("FOVEA_SCENE");  // pass-through: the session has nothing of the layer's
  const XrInstance instance = layer_.create_instance();
  EXPECT_EQ(find("xrCreateActionSet"), g.calls.size());
  XrSessionCreateInfo si{XR_TYPE_SESSION_CREATE_INFO};
  XrSession session = XR_NULL_HANDLE;
  ASSERT_EQ(layer_.get<PFN_xrCreateSession>(instance, "xrCreateSession")(instance, &si, &session), XR_SUCCESS);
  g.calls.clear();
  ASSERT_EQ(layer_.get<PFN_xrDestroyInstance>(instance, "xrDestroyInstance")(instance), XR_SUCCESS);
  EXPECT_EQ(g.calls, std::vector<std::string>{"xrDestroyInstance " + std::to_string(id(instance))});
}

// With a scene the layer enables XR_KHR_visibility_mask below itself; the application, which
// did not, neither gets its command nor its change events (consumed; the next poll's answer
// is returned). Enabled by the application, both pass through.
TEST_F(LayerChain, VisibilityMaskEnabledBelowStaysHidden) {
  g.visibility_mask = true;
  for (const bool app_enables : {false, true}) {
    SCOPED_TRACE(app_enables ? "the application enables it" : "the layer alone enables it");
    const XrInstance instance =
        app_enables ? layer_.create_instance({"XR_KHR_visibility_mask"}) : layer_.create_instance();
    ASSERT_NE(instance, XR_NULL_HANDLE);
    EXPECT_EQ(std::count(g.enabled.begin(), g.enabled.end(), "XR_KHR_visibility_mask"), 1);
    PFN_xrVoidFunction fn = nullptr;
    EXPECT_EQ(layer_.request.getInstanceProcAddr(instance, "xrGetVisibilityMaskKHR", &fn),
              app_enables ? XR_SUCCESS : XR_ERROR_FUNCTION_UNSUPPORTED);
    EXPECT_EQ(fn != nullptr, app_enables);
    g.mask_events = 2;
    g.count["xrPollEvent"] = 0;
    auto poll = layer_.get<PFN_xrPollEvent>(instance, "xrPollEvent");
    XrEventDataBuffer event{XR_TYPE_EVENT_DATA_BUFFER};
    if (app_enables) {
      EXPECT_EQ(poll(instance, &event), XR_SUCCESS);
      EXPECT_EQ(event.type, XR_TYPE_EVENT_DATA_VISIBILITY_MASK_CHANGED_KHR);
      EXPECT_EQ(g.count["xrPollEvent"], 1);
    } else {
      EXPECT_EQ(poll(instance, &event), XR_EVENT_UNAVAILABLE);
      EXPECT_EQ(event.type, XR_TYPE_EVENT_DATA_BUFFER);
      EXPECT_EQ(g.count["xrPollEvent"], 3);  // both events consumed
    }
    ASSERT_EQ(layer_.get<PFN_xrDestroyInstance>(instance, "xrDestroyInstance")(instance), XR_SUCCESS);
  }
}

// layer_timing.jsonl says which clock the runtime's XrTime values are on: converted to
// CLOCK_MONOTONIC with XR_KHR_convert_timespec_time when the runtime below offers it (the layer
// enables it for itself, the application still finds its commands unsupported), else kept as
// the runtime's XrTime and labelled so.
TEST_F(LayerChain, TimingRecordsSayWhichClockTheirXrTimesAreOn) {
  unsetenv("FOVEA_SCENE");
  for (const bool offered : {true, false}) {
    SCOPED_TRACE(offered ? "the runtime offers XR_KHR_convert_timespec_time" : "it does not");
    g = Fake{};
    g.convert_timespec = offered;
    const std::string out = "/tmp/fovea_layer_chain_clock_" + std::to_string(getpid()) + (offered ? "_on" : "_off");
    setenv("FOVEA_LAYER_OUT", out.c_str(), 1);
    const XrInstance instance = layer_.create_instance();
    EXPECT_EQ(std::count(g.enabled.begin(), g.enabled.end(), "XR_KHR_convert_timespec_time"), offered ? 1 : 0);
    PFN_xrVoidFunction f = nullptr;
    EXPECT_EQ(layer_.request.getInstanceProcAddr(instance, "xrConvertTimeToTimespecTimeKHR", &f),
              XR_ERROR_FUNCTION_UNSUPPORTED);
    XrSessionCreateInfo si{XR_TYPE_SESSION_CREATE_INFO};
    XrSession session = XR_NULL_HANDLE;
    ASSERT_EQ(layer_.get<PFN_xrCreateSession>(instance, "xrCreateSession")(instance, &si, &session), XR_SUCCESS);
    constexpr XrTime kDisplay = 5'000'000'000;
    XrFrameState fs{XR_TYPE_FRAME_STATE};
    fs.predictedDisplayTime = kDisplay;  // the fake's xrWaitFrame leaves it
    ASSERT_EQ(layer_.get<PFN_xrWaitFrame>(instance, "xrWaitFrame")(session, nullptr, &fs), XR_SUCCESS);
    ASSERT_EQ(layer_.get<PFN_xrBeginFrame>(instance, "xrBeginFrame")(session, nullptr), XR_SUCCESS);
    XrFrameEndInfo end{XR_TYPE_FRAME_END_INFO};
    end.displayTime = kDisplay;
    ASSERT_EQ(layer_.get<PFN_xrEndFrame>(instance, "xrEndFrame")(session, &end), XR_SUCCESS);
    ASSERT_EQ(layer_.get<PFN_xrDestroySession>(instance, "xrDestroySession")(session), XR_SUCCESS);  // records written
    ASSERT_EQ(layer_.get<PFN_xrDestroyInstance>(instance, "xrDestroyInstance")(instance), XR_SUCCESS);
    std::ifstream in(out + "/layer_timing.jsonl");
    std::string record;
    ASSERT_TRUE(std::getline(in, record)) << out;
    const XrTime expected = offered ? kDisplay - kXrTimeAhead : kDisplay;
    EXPECT_NE(record.find("\"predicted_display_ns\":" + std::to_string(expected) + ","), std::string::npos) << record;
    EXPECT_NE(record.find(std::string("\"xr_time_converted\":") + (offered ? "true" : "false")), std::string::npos)
        << record;
    std::filesystem::remove_all(out);
  }
  unsetenv("FOVEA_LAYER_OUT");
}

}  // namespace
