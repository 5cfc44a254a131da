// XR_APILAYER_FOVEA_path_tracing between an application and the Fovea runtime.
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <ostream>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "xr_fixture.hpp"
#include "xr_process.hpp"

#include "fovea/core/json.hpp"

namespace fovea::test {
namespace {

constexpr const char* kLayer = "XR_APILAYER_FOVEA_path_tracing";
constexpr int kFrames = 12;
constexpr int kPngEvery = 4;

std::vector<std::string> panel_files(const std::string& dir) {
  std::vector<std::string> v;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename().string().rfind("panel_", 0) == 0) v.push_back(e.path().filename().string());
  std::sort(v.begin(), v.end());
  return v;
}

size_t line_count(const std::string& path) {
  std::ifstream in(path);
  size_t n = 0;
  for (std::string l; std::getline(in, l);) ++n;
  return n;
}

ProcessResult hello_xr(const std::string& out, std::map<std::string, std::string> extra) {
  auto env = runtime_env(out, kFrames, kPngEvery);
  for (auto& [k, v] : extra) env[k] = v;
  return run_process({FOVEA_HELLO_XR, "-g", "Vulkan2"}, env, 120);
}

std::map<std::string, std::string> explicit_layer_env(const std::string& out) {
  return {{"XR_API_LAYER_PATH", FOVEA_LAYER_EXPLICIT_DIR},
          {"XR_ENABLE_API_LAYERS", kLayer},
          {"FOVEA_LAYER_OUT", out},
          {"FOVEA_LAYER_LOG_FILE", out + "/layer.log"},
          {"FOVEA_LAYER_SCENE", ""},
          {"FOVEA_SCENE", ""},
          {"XDG_CONFIG_HOME", out + "/no-config"}};
}

// With no scene the layer only measures: what the panel shows is byte-identical to a run
// without the layer. (The runtime's head pose and gaze are functions of the frame index
// and hello_xr's content depends only on the poses it locates, so both runs are
// deterministic per frame.)
TEST(Layer, PassThroughIsByteIdentical) {
  TempDir without("layer_off"), with("layer_on");
  const ProcessResult a = hello_xr(without.path(), {});
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const ProcessResult b = hello_xr(with.path(), explicit_layer_env(with.path()));
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const auto files = panel_files(without.path());
  ASSERT_EQ(files.size(), size_t(2 * (kFrames / kPngEvery)));
  ASSERT_EQ(panel_files(with.path()), files);
  for (const auto& f : files)
    EXPECT_EQ(read_text(without.path() + "/" + f), read_text(with.path() + "/" + f)) << f << " differs";
  // The layer was there: its log and one timing record per frame.
  const std::string log = read_text(with.path() + "/layer.log");
  EXPECT_NE(log.find("no scene: pass-through, measuring only"), std::string::npos) << log;
  EXPECT_NE(log.find("Vulkan device captured"), std::string::npos) << log;
  ASSERT_EQ(line_count(with.path() + "/layer_timing.jsonl"), size_t(kFrames));
  std::ifstream in(with.path() + "/layer_timing.jsonl");
  std::string line;
  for (int i = 0; std::getline(in, line); ++i) {
    const auto j = fovea::core::parse_json(line);
    EXPECT_EQ(j["frame"].get<int>(), i);
    EXPECT_FALSE(j["replaced"].get<bool>());
    EXPECT_GE(j["end_return_ns"].get<std::int64_t>(), j["end_call_ns"].get<std::int64_t>());
    if (i > 0) {
      EXPECT_EQ(j["projection_views"].get<int>(), 2);
    }
  }
  EXPECT_FALSE(std::filesystem::exists(without.path() + "/layer_timing.jsonl"));
}

// Implicit manifest: loaded from an implicit.d search directory without being enabled;
// its disable_environment variable turns it off.
TEST(Layer, ImplicitManifestAndDisableEnvironment) {
  TempDir data("layer_xdg");
  const auto dir = std::filesystem::path(data.path()) / "openxr/1/api_layers/implicit.d";
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(std::string(FOVEA_LAYER_IMPLICIT_DIR) + "/XrApiLayer_fovea.json", dir / "XrApiLayer_fovea.json");
  for (const bool disabled : {false, true}) {
    TempDir out("layer_implicit");
    const ProcessResult r = hello_xr(out.path(), {{"XDG_DATA_HOME", data.path()},
                                                  {"FOVEA_LAYER_OUT", out.path()},
                                                  {"DISABLE_XR_APILAYER_FOVEA_PATH_TRACING", disabled ? "1" : ""}});
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(std::filesystem::exists(out.path() + "/layer_timing.jsonl"), !disabled) << "disabled=" << disabled;
  }
}

// The layer and the Khronos core validation layer together: still clean.
TEST(Layer, CoreValidationWithLayer) {
  TempDir out("layer_cv");
  auto env = explicit_layer_env(out.path());
  env["XR_ENABLE_API_LAYERS"] = std::string("XR_APILAYER_LUNARG_core_validation:") + kLayer;
  // XR_API_LAYER_PATH replaces the explicit search path: add Debian's directory back.
  env["XR_API_LAYER_PATH"] = std::string(FOVEA_LAYER_EXPLICIT_DIR) + ":/usr/share/openxr/1/api_layers/explicit.d";
  env["XR_CORE_VALIDATION_EXPORT_TYPE"] = "text";
  env["XR_CORE_VALIDATION_FILE_NAME"] = out.path() + "/core_validation.txt";
  env["XR_LOADER_DEBUG"] = "info";
  const ProcessResult r = hello_xr(out.path(), env);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("succeeded loading layer XR_APILAYER_LUNARG_core_validation"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(std::string("succeeded loading layer ") + kLayer), std::string::npos) << r.output;
  const std::string cv = read_text(out.path() + "/core_validation.txt");
  EXPECT_EQ(cv.find("VUID-"), std::string::npos) << cv;
  EXPECT_EQ(line_count(out.path() + "/layer_timing.jsonl"), size_t(kFrames));
}

// The core validation layer below the layer, with a scene (the layer then asks below it
// whether the runtime offers eye gaze): no internal validation error at start-up (it came
// from asking core validation for a global command without an instance), no VUID.
TEST(Layer, CoreValidationBelowLayerWithScene) {
  TempDir out("layer_cv_below");
  auto env = explicit_layer_env(out.path());
  env["XR_ENABLE_API_LAYERS"] = std::string(kLayer) + ":XR_APILAYER_LUNARG_core_validation";
  env["XR_API_LAYER_PATH"] = std::string(FOVEA_LAYER_EXPLICIT_DIR) + ":/usr/share/openxr/1/api_layers/explicit.d";
  env["XR_CORE_VALIDATION_EXPORT_TYPE"] = "text";
  env["XR_CORE_VALIDATION_FILE_NAME"] = out.path() + "/core_validation.txt";
  env["FOVEA_SCENE"] = "cornell";
  env["FOVEA_DISPLAY"] = "tiny";
  env["FOVEA_EXIT_AFTER_FRAMES"] = "2";
  const ProcessResult r = hello_xr(out.path(), env);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output.find("INTERNAL VALIDATION LAYER ERROR"), std::string::npos) << r.output;
  // The runtime's eye gaze is still used with a layer below.
  const std::string log = read_text(out.path() + "/layer.log");
  EXPECT_NE(log.find("merged into the application's action sets"), std::string::npos) << log;
  const std::string cv = read_text(out.path() + "/core_validation.txt");
  EXPECT_EQ(cv.find("VUID-"), std::string::npos) << cv;
}

class LayerApiTest : public XrTest {
 protected:
  void SetUp() override {
    XrTest::SetUp();
    log_ = std::make_unique<TempDir>("layer_api");
    setenv("XR_API_LAYER_PATH", FOVEA_LAYER_EXPLICIT_DIR, 1);
    setenv("XR_ENABLE_API_LAYERS", kLayer, 1);
    setenv("FOVEA_LAYER_OUT", log_->path().c_str(), 1);
  }
  void TearDown() override {
    XrTest::TearDown();
    unsetenv("XR_API_LAYER_PATH");
    unsetenv("XR_ENABLE_API_LAYERS");
    unsetenv("FOVEA_LAYER_OUT");
    unsetenv("FOVEA_LAYER_SCENE");
  }
  std::unique_ptr<TempDir> log_;
};

// The loader accepts the layer's own extension (from the manifest); the layer strips it
// before calling down, so the runtime, which does not know it, still creates the instance.
TEST_F(LayerApiTest, OwnExtensionIsStrippedBeforeTheRuntime) {
  uint32_t n = 0;
  ASSERT_EQ(xrEnumerateInstanceExtensionProperties(kLayer, 0, &n, nullptr), XR_SUCCESS);
  std::vector<XrExtensionProperties> props(n, {XR_TYPE_EXTENSION_PROPERTIES});
  ASSERT_EQ(xrEnumerateInstanceExtensionProperties(kLayer, n, &n, props.data()), XR_SUCCESS);
  ASSERT_EQ(n, 1u);
  EXPECT_STREQ(props[0].extensionName, "XR_FOVEA_path_tracing");
  create_instance({"XR_FOVEA_path_tracing"});
  run_to_focused();
  ASSERT_EQ(frame(), XR_SUCCESS);
}

// What an application can observe of the layer's presence in the extension list: the
// layer's own XR_FOVEA_path_tracing (its manifest's, answered by the loader) and nothing else;
// the extensions the layer enables below itself are listed exactly when the runtime lists them.
TEST_F(LayerApiTest, ExtensionListGainsOnlyTheLayersOwnExtension) {
  setenv("FOVEA_LAYER_SCENE", "cornell", 1);
  const auto names = [] {
    uint32_t n = 0;
    EXPECT_EQ(xrEnumerateInstanceExtensionProperties(nullptr, 0, &n, nullptr), XR_SUCCESS);
    std::vector<XrExtensionProperties> props(n, {XR_TYPE_EXTENSION_PROPERTIES});
    EXPECT_EQ(xrEnumerateInstanceExtensionProperties(nullptr, n, &n, props.data()), XR_SUCCESS);
    std::set<std::string> v;
    for (uint32_t i = 0; i < n; ++i) v.insert(props[i].extensionName);
    return v;
  };
  const std::set<std::string> layered = names();
  unsetenv("XR_ENABLE_API_LAYERS");
  std::set<std::string> expected = names();
  EXPECT_EQ(expected.count("XR_FOVEA_path_tracing"), 0u);
  EXPECT_EQ(expected.count("XR_EXT_eye_gaze_interaction"), 1u);
  expected.insert("XR_FOVEA_path_tracing");
  EXPECT_EQ(layered, expected);
}

// The layer's eye-gaze action set has a name and a localized name with a random tag per
// instance: an application's action sets named like the layer's former fixed name
// (`xr_apilayer_fovea_gaze`) or with its former localized name ("Fovea layer eye gaze") are
// created (they were XR_ERROR_NAME_DUPLICATED and XR_ERROR_LOCALIZED_NAME_DUPLICATED), with
// and without the application enabling the extension.
TEST_F(LayerApiTest, ApplicationActionSetNamesNeverCollideWithTheLayers) {
  setenv("FOVEA_LAYER_SCENE", "cornell", 1);
  setenv("FOVEA_RUNTIME_OUT", log_->path().c_str(), 1);
  for (const bool enable : {false, true}) {
    SCOPED_TRACE(enable ? "extension enabled" : "extension not enabled");
    std::vector<const char*> ext;
    if (enable) ext.push_back("XR_EXT_eye_gaze_interaction");
    ASSERT_NO_FATAL_FAILURE(create_instance(ext));
    XrActionSetCreateInfo named{XR_TYPE_ACTION_SET_CREATE_INFO};
    std::strcpy(named.actionSetName, "xr_apilayer_fovea_gaze");
    std::strcpy(named.localizedActionSetName, "App gaze");
    XrActionSetCreateInfo localized{XR_TYPE_ACTION_SET_CREATE_INFO};
    std::strcpy(localized.actionSetName, "app_gaze");
    std::strcpy(localized.localizedActionSetName, "Fovea layer eye gaze");
    XrActionSet sets[2] = {XR_NULL_HANDLE, XR_NULL_HANDLE};
    EXPECT_EQ(xrCreateActionSet(instance_, &named, &sets[0]), XR_SUCCESS);
    EXPECT_EQ(xrCreateActionSet(instance_, &localized, &sets[1]), XR_SUCCESS);
    ASSERT_NO_FATAL_FAILURE(create_session());
    XrSessionActionSetsAttachInfo attach{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
    attach.countActionSets = 2;
    attach.actionSets = sets;
    EXPECT_EQ(xrAttachSessionActionSets(session_, &attach), XR_SUCCESS);
    // Not vacuous: the layer's own set with its eye-gaze binding rode along (the runtime's log).
    const std::string log = read_text(log_->path() + "/runtime.log");
    EXPECT_NE(log.find("action sets attached: 3, eye gaze bound"), std::string::npos) << log;
    end_instance();
  }
  unsetenv("FOVEA_RUNTIME_OUT");
}

// The timing log's XrTime values (the predicted display time, here) are converted to
// CLOCK_MONOTONIC, the clock of the layer's own stamps, with XR_KHR_convert_timespec_time,
// which the layer enables below itself while the application, which did not enable it, still
// finds its commands unsupported; `frame` is the application's frame index. (The project's
// runtime's XrTime is CLOCK_MONOTONIC: converted, the values stay the ones it predicted.)
TEST_F(LayerApiTest, TimingRecordsAreOnOneClock) {
  for (const bool app_enables : {false, true}) {
    SCOPED_TRACE(app_enables ? "the application enabled XR_KHR_convert_timespec_time" : "not enabled by the application");
    std::vector<const char*> ext;
    if (app_enables) ext.push_back("XR_KHR_convert_timespec_time");
    ASSERT_NO_FATAL_FAILURE(create_instance(ext));
    for (const char* fn : {"xrConvertTimeToTimespecTimeKHR", "xrConvertTimespecTimeToTimeKHR"}) {
      PFN_xrVoidFunction f = nullptr;
      EXPECT_EQ(xrGetInstanceProcAddr(instance_, fn, &f), app_enables ? XR_SUCCESS : XR_ERROR_FUNCTION_UNSUPPORTED) << fn;
      EXPECT_EQ(f != nullptr, app_enables) << fn;
    }
    ASSERT_NO_FATAL_FAILURE(run_to_focused());
    std::vector<XrTime> predicted;
    for (int f = 0; f < 3; ++f) {
      XrFrameState fs{XR_TYPE_FRAME_STATE};
      ASSERT_EQ(frame({}, &fs), XR_SUCCESS);
      predicted.push_back(fs.predictedDisplayTime);
    }
    end_instance();  // the session's records are complete once it is destroyed
    std::vector<nlohmann::json> recs;
    std::ifstream in(log_->path() + "/layer_timing.jsonl");
    for (std::string line; std::getline(in, line);) recs.push_back(core::parse_json(line));
    // This instance's session: run_to_focused's frame and the three above, last in the file.
    ASSERT_GE(recs.size(), 4u);
    const std::vector<nlohmann::json> mine(recs.end() - 4, recs.end());
    for (std::size_t i = 0; i < mine.size(); ++i) {
      const nlohmann::json& r = mine[i];
      EXPECT_EQ(r["clock"], "monotonic") << r.dump();
      EXPECT_TRUE(r["xr_time_converted"].get<bool>()) << r.dump();
      EXPECT_EQ(r["frame"].get<std::int64_t>(), std::int64_t(i)) << r.dump();
      EXPECT_EQ(r["traced_frame"].get<std::int64_t>(), -1) << r.dump();  // no scene: nothing traced
      EXPECT_EQ(r["traced_for_frame"].get<std::int64_t>(), -1) << r.dump();
      if (i > 0) {
        EXPECT_EQ(r["predicted_display_ns"].get<std::int64_t>(), predicted[i - 1]) << r.dump();
      }
      EXPECT_TRUE(r["vsync_ns"].is_null()) << "OpenXR gives the application no vsync: " << r.dump();
    }
  }
}

// With a scene the layer enables XR_KHR_visibility_mask below itself for culling, unseen by
// the application: the command stays unsupported unless the application enables the
// extension itself, in which case it reaches the runtime and answers.
TEST_F(LayerApiTest, VisibilityMaskStaysTheApplicationsChoice) {
  setenv("FOVEA_LAYER_SCENE", "cornell", 1);
  PFN_xrVoidFunction f = nullptr;
  create_instance({});
  EXPECT_EQ(xrGetInstanceProcAddr(instance_, "xrGetVisibilityMaskKHR", &f), XR_ERROR_FUNCTION_UNSUPPORTED);
  EXPECT_EQ(f, nullptr);
  ASSERT_EQ(xrDestroyInstance(instance_), XR_SUCCESS);
  instance_ = XR_NULL_HANDLE;

  create_instance({"XR_KHR_visibility_mask"});
  ASSERT_EQ(xrGetInstanceProcAddr(instance_, "xrGetVisibilityMaskKHR", &f), XR_SUCCESS);
  ASSERT_NE(f, nullptr);
  create_session();
  XrVisibilityMaskKHR m{XR_TYPE_VISIBILITY_MASK_KHR};
  EXPECT_EQ(reinterpret_cast<PFN_xrGetVisibilityMaskKHR>(f)(session_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0,
                                                            XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR, &m),
            XR_SUCCESS);
}

// What an application observes of eye gaze and its actions (codes, properties, profiles, events).
struct Observed {
  XrBool32 supports_eye_gaze = 2;  // neither XR_TRUE nor XR_FALSE: whether it was written
  XrResult eyes_action = XR_SUCCESS, suggest_gaze = XR_SUCCESS, suggest_hand = XR_SUCCESS;
  XrResult attach_none = XR_SUCCESS, profile_before = XR_SUCCESS, attach = XR_SUCCESS;
  XrResult eyes = XR_SUCCESS, hand = XR_SUCCESS;
  XrResult sync_eyes = XR_SUCCESS, sync_hand = XR_SUCCESS;  // xrSyncActions with that subaction path
  XrResult begin = XR_SUCCESS, sync_running = XR_SUCCESS;   // then xrBeginSession and a sync of all
  std::vector<XrStructureType> events;
  std::string eyes_profile_name, hand_profile_name;  // paths differ between instances: compared as strings
};

bool operator==(const Observed& a, const Observed& b) {
  return a.supports_eye_gaze == b.supports_eye_gaze && a.eyes_action == b.eyes_action && a.suggest_gaze == b.suggest_gaze &&
         a.suggest_hand == b.suggest_hand && a.attach_none == b.attach_none && a.profile_before == b.profile_before &&
         a.attach == b.attach && a.eyes == b.eyes && a.hand == b.hand && a.sync_eyes == b.sync_eyes &&
         a.sync_hand == b.sync_hand && a.begin == b.begin && a.sync_running == b.sync_running && a.events == b.events &&
         a.eyes_profile_name == b.eyes_profile_name && a.hand_profile_name == b.hand_profile_name;
}

std::ostream& operator<<(std::ostream& os, const Observed& o) {
  os << "{supports " << o.supports_eye_gaze << ", action on /user/eyes_ext " << o.eyes_action << ", suggest gaze " << o.suggest_gaze << " hand " << o.suggest_hand
     << ", attach none " << o.attach_none << ", profile before attach " << o.profile_before << ", attach " << o.attach
     << ", eyes " << o.eyes << " '" << o.eyes_profile_name << "', hand " << o.hand << " '" << o.hand_profile_name
     << "', sync /user/eyes_ext " << o.sync_eyes << " /user/hand/left " << o.sync_hand << ", begin " << o.begin
     << ", sync running " << o.sync_running << ", events";
  for (XrStructureType t : o.events) os << " " << int(t);
  return os << "}";
}

// The application's eye-gaze and action calls through whatever layers are enabled: a pose
// action suggested for the eye-gaze profile (when `suggest_gaze`) and the simple controller,
// attach with no set, then with its set, syncs before the session runs and one after xrBeginSession,
// the profiles and the events that follow.
Observed observe(XrInstance instance, const XrSession& session, bool suggest_gaze,
                 const std::function<void()>& create_session, const std::function<XrPath(const char*)>& path) {
  Observed o;
  XrSystemEyeGazeInteractionPropertiesEXT gp{XR_TYPE_SYSTEM_EYE_GAZE_INTERACTION_PROPERTIES_EXT};
  gp.supportsEyeGazeInteraction = 2;
  XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES, &gp};
  XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
  gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  XrSystemId system = XR_NULL_SYSTEM_ID;
  EXPECT_EQ(xrGetSystem(instance, &gi, &system), XR_SUCCESS);
  EXPECT_EQ(xrGetSystemProperties(instance, system, &sp), XR_SUCCESS);
  o.supports_eye_gaze = gp.supportsEyeGazeInteraction;

  XrActionSetCreateInfo si{XR_TYPE_ACTION_SET_CREATE_INFO};
  std::strcpy(si.actionSetName, "app");
  std::strcpy(si.localizedActionSetName, "App");
  XrActionSet set = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateActionSet(instance, &si, &set), XR_SUCCESS);
  XrActionCreateInfo ai{XR_TYPE_ACTION_CREATE_INFO};
  ai.actionType = XR_ACTION_TYPE_POSE_INPUT;
  std::strcpy(ai.actionName, "aim");
  std::strcpy(ai.localizedActionName, "Aim");
  XrAction aim = XR_NULL_HANDLE;
  EXPECT_EQ(xrCreateAction(set, &ai, &aim), XR_SUCCESS);
  XrActionCreateInfo eyes_ai = ai;
  std::strcpy(eyes_ai.actionName, "look");
  std::strcpy(eyes_ai.localizedActionName, "Look");
  const XrPath eyes_path = path("/user/eyes_ext");
  eyes_ai.countSubactionPaths = 1;
  eyes_ai.subactionPaths = &eyes_path;
  XrAction look = XR_NULL_HANDLE;
  o.eyes_action = xrCreateAction(set, &eyes_ai, &look);
  const auto suggest = [&](const char* profile, const char* binding) {
    const XrActionSuggestedBinding b{aim, path(binding)};
    XrInteractionProfileSuggestedBinding sb{XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING};
    sb.interactionProfile = path(profile);
    sb.countSuggestedBindings = 1;
    sb.suggestedBindings = &b;
    return xrSuggestInteractionProfileBindings(instance, &sb);
  };
  if (suggest_gaze)
    o.suggest_gaze = suggest("/interaction_profiles/ext/eye_gaze_interaction", "/user/eyes_ext/input/gaze_ext/pose");
  o.suggest_hand = suggest("/interaction_profiles/khr/simple_controller", "/user/hand/left/input/aim/pose");
  create_session();
  XrSessionActionSetsAttachInfo none{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  o.attach_none = xrAttachSessionActionSets(session, &none);
  XrInteractionProfileState ps{XR_TYPE_INTERACTION_PROFILE_STATE};
  o.profile_before = xrGetCurrentInteractionProfile(session, path("/user/eyes_ext"), &ps);
  XrSessionActionSetsAttachInfo attach{XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO};
  attach.countActionSets = 1;
  attach.actionSets = &set;
  o.attach = xrAttachSessionActionSets(session, &attach);
  // Before the session runs: no profile becomes current, no event (the runtime changes
  // profiles only in xrSyncActions of a running session).
  const auto sync = [&](const char* subaction) {
    const XrActiveActionSet active{set, subaction ? path(subaction) : XrPath(XR_NULL_PATH)};
    XrActionsSyncInfo sync_info{XR_TYPE_ACTIONS_SYNC_INFO};
    sync_info.countActiveActionSets = 1;
    sync_info.activeActionSets = &active;
    return xrSyncActions(session, &sync_info);
  };
  o.sync_eyes = sync("/user/eyes_ext");
  o.sync_hand = sync("/user/hand/left");
  const auto poll = [&] {
    for (;;) {
      XrEventDataBuffer e{XR_TYPE_EVENT_DATA_BUFFER};
      if (xrPollEvent(instance, &e) != XR_SUCCESS) break;
      o.events.push_back(e.type);
    }
  };
  poll();  // IDLE, READY
  XrSessionBeginInfo bi{XR_TYPE_SESSION_BEGIN_INFO};
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  o.begin = xrBeginSession(session, &bi);
  o.sync_running = sync(nullptr);
  const auto name = [&](XrPath p) {
    if (p == XR_NULL_PATH) return std::string("null");
    char buf[XR_MAX_PATH_LENGTH];
    uint32_t n = 0;
    return xrPathToString(instance, p, sizeof buf, &n, buf) == XR_SUCCESS ? std::string(buf) : std::string("?");
  };
  ps = {XR_TYPE_INTERACTION_PROFILE_STATE};
  o.eyes = xrGetCurrentInteractionProfile(session, path("/user/eyes_ext"), &ps);
  o.eyes_profile_name = o.eyes == XR_SUCCESS ? name(ps.interactionProfile) : "";
  ps = {XR_TYPE_INTERACTION_PROFILE_STATE};
  o.hand = xrGetCurrentInteractionProfile(session, path("/user/hand/left"), &ps);
  o.hand_profile_name = o.hand == XR_SUCCESS ? name(ps.interactionProfile) : "";
  poll();  // the profile change of the running session's sync, if the application sees one
  return o;
}

// With a scene the layer reads the eye tracker through the runtime's eye-gaze action, enabling
// XR_EXT_eye_gaze_interaction below itself: the application sees exactly what it sees without
// the layer, whether it enabled the extension or not, suggested eye-gaze bindings or not.
TEST_F(LayerApiTest, EyeGazeStaysTheApplicationsChoice) {
  setenv("FOVEA_LAYER_SCENE", "cornell", 1);
  struct Case {
    bool enable, suggest;
  };
  for (const Case c : {Case{false, true}, Case{true, false}, Case{true, true}}) {
    SCOPED_TRACE(std::string("extension ") + (c.enable ? "enabled" : "not enabled") + ", eye-gaze bindings " +
                 (c.suggest ? "suggested" : "not suggested"));
    Observed seen[2];
    for (int layered = 1; layered >= 0; --layered) {
      if (!layered) unsetenv("XR_ENABLE_API_LAYERS");
      std::vector<const char*> ext;
      if (c.enable) ext.push_back("XR_EXT_eye_gaze_interaction");
      ASSERT_NO_FATAL_FAILURE(create_instance(ext));
      seen[layered] = observe(instance_, session_, c.suggest, [&] { create_session(); },
                              [&](const char* s) { return path(s); });
      end_instance();
      setenv("XR_ENABLE_API_LAYERS", kLayer, 1);
    }
    EXPECT_EQ(seen[1], seen[0]) << "through the layer: " << seen[1] << "\nwithout it: " << seen[0];
    // Not vacuous: attaching no set is an error, and the eye tracker's profile is current
    // exactly when the application bound it.
    EXPECT_EQ(seen[0].attach_none, XR_ERROR_VALIDATION_FAILURE);
    EXPECT_EQ(seen[0].eyes_action, c.enable ? XR_SUCCESS : XR_ERROR_PATH_UNSUPPORTED);
    EXPECT_EQ(seen[0].supports_eye_gaze, c.enable ? XR_TRUE : XR_FALSE);
    // The session is not focused: a sync the runtime accepts answers XR_SESSION_NOT_FOCUSED.
    EXPECT_EQ(seen[0].sync_eyes, c.enable ? XR_SESSION_NOT_FOCUSED : XR_ERROR_PATH_UNSUPPORTED);
    EXPECT_EQ(seen[0].sync_hand, XR_SESSION_NOT_FOCUSED);
    EXPECT_EQ(seen[0].eyes_profile_name == "/interaction_profiles/ext/eye_gaze_interaction", c.enable && c.suggest);
    EXPECT_EQ(seen[0].begin, XR_SUCCESS);
    EXPECT_EQ(seen[0].sync_running, XR_SESSION_NOT_FOCUSED);
    EXPECT_EQ(std::count(seen[0].events.begin(), seen[0].events.end(), XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED),
              c.enable && c.suggest ? 1 : 0);
  }
}

// Error codes come from the runtime unchanged through the layer's intercepts.
TEST_F(LayerApiTest, ErrorsPassThrough) {
  create_instance();
  create_session();
  XrFrameState fs{XR_TYPE_FRAME_STATE};
  EXPECT_EQ(xrWaitFrame(session_, nullptr, &fs), XR_ERROR_SESSION_NOT_RUNNING);
  EXPECT_EQ(xrBeginFrame(session_, nullptr), XR_ERROR_SESSION_NOT_RUNNING);
  EXPECT_EQ(xrWaitFrame(reinterpret_cast<XrSession>(0xbad), nullptr, &fs), XR_ERROR_HANDLE_INVALID);
  uint32_t idx = 0;
  EXPECT_EQ(xrAcquireSwapchainImage(reinterpret_cast<XrSwapchain>(0xbad), nullptr, &idx), XR_ERROR_HANDLE_INVALID);
  XrFrameEndInfo ei{XR_TYPE_FRAME_END_INFO};
  EXPECT_EQ(xrEndFrame(session_, &ei), XR_ERROR_SESSION_NOT_RUNNING);
}

// A scene the layer cannot render disables the layer for the session: frames pass through.
TEST_F(LayerApiTest, FailureDisablesTheLayerForTheSession) {
  setenv("FOVEA_LAYER_SCENE", "some-scene.gltf", 1);
  create_instance({"XR_FOVEA_path_tracing"});
  run_to_focused();
  ASSERT_EQ(frame(), XR_SUCCESS);
  // Disabled: no frame is timed either.
  EXPECT_EQ(line_count(log_->path() + "/layer_timing.jsonl"), 0u);
}

}  // namespace
}  // namespace fovea::test
