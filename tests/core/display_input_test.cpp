// Display presets and lens parameters from outside: every malformed value is an
// InputError naming the file and the key (fuzz findings: a non-string "name" and a
// number beyond the range of double used to escape as raw JSON-library errors).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <unistd.h>

#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/input_limits.hpp"
#include "fovea/core/lens_params.hpp"
#include "fovea/core/stereo_views.hpp"

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

namespace {
std::string preset(const std::string& extra) {
  return R"({"name":"t","width":64,"height":72,)" + kFov + extra + "}";
}
const std::string kLens =
    R"("model":"panotools","aberration":[0.999,1.008,1.018],"centre":[0.5,0.5],"scale":1.2,"cutoff":0.45)";
}  // namespace

// A 1e-9 Hz display hung `fovea render` (its second frame lies 30 years into the gaze).
TEST(DisplayInput, RefreshRateHasAPhysicalRange) {
  for (const char* hz : {"1e-9", "0.5", "0", "-70", "1001"}) expect_error(preset(std::string(R"(,"refresh_hz":)") + hz), "\"refresh_hz\" must be in [1, 1000] Hz");
  EXPECT_DOUBLE_EQ(parse_display(preset(R"(,"refresh_hz":1)"), "p").refresh_hz, 1.0);
  EXPECT_DOUBLE_EQ(parse_display(preset(R"(,"refresh_hz":1000)"), "p").refresh_hz, 1000.0);
}

// 16384² and 65536² rasters hung `fovea density` and ran `lens`/`render` out of memory; an
// 8k-per-eye display still loads.
TEST(DisplayInput, RasterIsBoundedPerEyeAndEightKFits) {
  const auto raster = [](const std::string& w, const std::string& h) {
    return R"({"name":"t","width":)" + w + R"(,"height":)" + h + "," + kFov + "}";
  };
  expect_error(raster("16384", "16384"), "\"width\" must be a whole number of pixels in 1..8192");
  expect_error(raster("65536", "64"), "\"width\"");
  expect_error(raster("64", "8193"), "\"height\" must be a whole number of pixels in 1..8192");
  expect_error(raster("64.5", "64"), "\"width\"");
  const DisplayPreset d = parse_display(raster(std::to_string(kMaxEyePixels), std::to_string(kMaxEyePixels)), "p");
  EXPECT_EQ(d.width, 8192);
  EXPECT_EQ(d.height, 8192);
}

// A negative IPD swapped the eyes; 1e30 put them outside every scene (black frames).
TEST(DisplayInput, IpdMustBeAnAdultsOrZero) {
  for (const char* ipd : {"-0.063", "1e30", "0.2"}) expect_error(preset(std::string(R"(,"ipd_m":)") + ipd), "\"ipd_m\" must be in [0, 0.1] m");
  EXPECT_DOUBLE_EQ(parse_display(preset(R"(,"ipd_m":0)"), "p").ipd_m, 0.0);
  EXPECT_DOUBLE_EQ(parse_display(preset(R"(,"ipd_m":0.07)"), "p").ipd_m, 0.07);
}

// k = 1e30 kept the radial map increasing but hid every panel pixel (hidden fraction 1.0,
// garbage frames): refused at load, naming the file and the lens.
TEST(DisplayInput, LensWithoutVisibleAreaIsRefused) {
  expect_error(preset(R"(,"lens":{"k":[1e30,0,0,0,0],)" + kLens + "}"), "lens (left eye)");
  expect_error(preset(R"(,"lens":{"k":[1e30,0,0,0,0],)" + kLens + "}"), "no usable area");
  // The shipped coefficients load, and their error names nothing.
  const DisplayPreset d = parse_display(preset(R"(,"lens":{"k":[0.75,-0.01,0.75,0,3.8],)" + kLens + "}"), "p");
  EXPECT_EQ(d.origin, "p");
  for (const auto& name : display_preset_names()) EXPECT_NO_THROW((void)load_display(name)) << name;
}

// Canted panels: each eye turned outwards about the head's up axis, within [0, 45]°.
TEST(DisplayInput, CantMustBeBetweenZeroAndFortyFiveDegrees) {
  for (const char* cant : {"-5", "60", "1e30"})
    expect_error(preset(std::string(R"(,"cant_deg":)") + cant), "\"cant_deg\" must be in [0, 45] degrees");
  EXPECT_DOUBLE_EQ(parse_display(preset(R"(,"cant_deg":12.5)"), "p").cant_deg, 12.5);
  EXPECT_DOUBLE_EQ(parse_display(preset(""), "p").cant_deg, 0.0);
}

// The wide preset: 125° per eye, panels canted 20° outwards, so the two eyes together see
// 190° horizontally (75° + 20° towards each temple) and 60° with both eyes.
TEST(WidePreset, CantedPanelsSee190DegreesBinocular) {
  const DisplayPreset d = load_display("wide");
  const StereoViews v = stereo_views(d);
  const auto yaw_deg = [](const View& view, glm::dvec2 px) {
    const glm::dvec3 w = view.pose().orientation * view.pixel_to_dir(px);  // head frame
    return std::atan2(w.x, -w.z) * 180 / std::numbers::pi;
  };
  const double h = 0.5 * d.height;
  EXPECT_NEAR(yaw_deg(v[Eye::Left], {0, h}), -95, 1e-6);            // left eye's temple edge
  EXPECT_NEAR(yaw_deg(v[Eye::Left], {double(d.width), h}), 30, 1e-6);  // its nasal edge
  EXPECT_NEAR(yaw_deg(v[Eye::Right], {double(d.width), h}), 95, 1e-6);
  EXPECT_NEAR(yaw_deg(v[Eye::Right], {0, h}), -30, 1e-6);
  // The eyes still sit ipd/2 beside the head, on its x axis.
  EXPECT_NEAR(v[Eye::Left].pose().position.x, -0.5 * d.ipd_m, 1e-12);
  EXPECT_NEAR(v[Eye::Right].pose().position.x, 0.5 * d.ipd_m, 1e-12);
}
