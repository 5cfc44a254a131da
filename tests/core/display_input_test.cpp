// Display presets and lens parameters from outside: every malformed value is an
// InputError naming the file and the key (fuzz findings: a non-string "name" and a
// number beyond the range of double used to escape as raw JSON-library errors).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/input_limits.hpp"
#include "fovea/core/lens_params.hpp"

using namespace fovea::core;

namespace {

const std::string kFov = R"("fov_deg":{"left":-50,"right":50,"up":53,"down":-53})";

std::string error_of(const std::string& text) {
  try {
    (void)parse_display(text, "preset.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

void expect_error(const std::string& text, const std::string& key) {
  const std::string e = error_of(text);
  EXPECT_NE(e.find("preset.json"), std::string::npos) << e;
  EXPECT_NE(e.find(key), std::string::npos) << e;
  EXPECT_EQ(e.find("[json.exception"), std::string::npos) << e;
}

}  // namespace

TEST(DisplayInput, WrongTypesNameTheKey) {
  expect_error(R"({"name":3,"width":64,"height":64,)" + kFov + "}", "\"name\"");
  expect_error(R"({"name":"t","description":[1],"width":64,"height":64,)" + kFov + "}", "\"description\"");
  expect_error(R"({"name":"t","width":64,"height":64,)" + kFov + R"(,"lens":{"model":"vive","source":7}})",
               "lens.source");
}

TEST(DisplayInput, NumbersBeyondDoubleNameTheKey) {
  expect_error(R"({"name":"t","width":1e400,"height":64,)" + kFov + "}", "\"width\"");
  expect_error(R"({"name":"t","width":64,"height":64,"fov_deg":{"left":-1e999,"right":50,"up":53,"down":-53}})",
               "\"left\"");
}

TEST(DisplayInput, DeepNestingIsRefusedBeforeParsing) {
  const std::string deep = R"({"name":"t","x":)" + std::string(100000, '[') + std::string(100000, ']') + "}";
  expect_error(deep, "nested deeper than");
  EXPECT_EQ(json_nesting_depth(R"({"a":"[[[[","b":[{"c":"\"]["}]})", 100), 3u);
  EXPECT_EQ(json_nesting_depth(std::string(1000, '['), 10), 10u);
}

TEST(DisplayInput, FilesAreReadBounded) {
  const auto dir = std::filesystem::temp_directory_path() / ("fovea_display_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto big = (dir / "big.json").string();
  std::ofstream(big) << std::string(2 << 20, ' ') << "{}";
  EXPECT_THROW((void)load_display(big), InputError);
  EXPECT_THROW((void)read_file_bounded("/dev/zero", 1024), InputError);  // not a regular file
  EXPECT_EQ(read_file_bounded(big, 4 << 20).size(), (2u << 20) + 2);
  EXPECT_THROW((void)read_file_bounded(big, 1 << 20), InputError);
  std::filesystem::remove_all(dir);
}
