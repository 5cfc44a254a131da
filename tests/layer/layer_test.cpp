// XR_APILAYER_FOVEA_path_tracing between an application and the Fovea runtime.
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "xr_fixture.hpp"
#include "xr_process.hpp"

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
    const auto j = nlohmann::json::parse(line);
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
