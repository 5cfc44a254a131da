// `fovea xr-info` sees the Fovea runtime and layer through the real loader.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "xr_process.hpp"

#include "fovea/core/json.hpp"

namespace fovea::test {
namespace {

TEST(XrInfo, ReportsRuntimeAndLayer) {
  TempDir out("xr_info");
  auto env = runtime_env(out.path(), 0, 1);
  const ProcessResult r = run_process({FOVEA_CLI, "xr-info", "--json", "--runtime-json", FOVEA_RUNTIME_MANIFEST,
                                       "--layer-path", FOVEA_LAYER_EXPLICIT_DIR},
                                      env, 60);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto json_start = r.output.find('{');
  ASSERT_NE(json_start, std::string::npos) << r.output;
  const auto j = fovea::core::parse_json(r.output.substr(json_start, r.output.rfind('}') - json_start + 1));
  EXPECT_EQ(j["runtime_manifest"]["source"], "XR_RUNTIME_JSON");
  EXPECT_TRUE(j["runtime"]["loads"].get<bool>());
  EXPECT_TRUE(j["runtime"]["is_fovea"].get<bool>());
  EXPECT_EQ(j["runtime"]["system_name"], "Fovea simulated HMD (small)");
  EXPECT_TRUE(j["fovea_layer"]["found"].get<bool>());
  EXPECT_TRUE(j["fovea_layer"]["loads"].get<bool>()) << j.dump(2);
}

TEST(XrInfo, BadArgumentsExitWithTwo) {
  const ProcessResult r = run_process({FOVEA_CLI, "xr-info", "--runtime-json", "/no/such/manifest.json"}, {}, 60);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("/no/such/manifest.json"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace fovea::test
