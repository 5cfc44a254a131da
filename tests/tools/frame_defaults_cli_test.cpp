// Every entry point of the pipeline starts from the same frame: `fovea render`, `fovea
// latency` and `fovea view` report the frame options they ran with, which without options
// are pipeline::FrameConfig's defaults (the layer's: FrameConfigLayer.* in tests/layer).
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "fovea/core/json.hpp"
#include "fovea/pipeline/frame_config.hpp"
#include "xvfb.hpp"

namespace frame_defaults {

namespace fs = std::filesystem;
using fovea::test::run_fovea;

nlohmann::json config_of(const std::string& file) {
  std::ifstream in(file);
  return fovea::core::parse_json(in).at("config").at("frame_options");
}

TEST(FrameDefaults, RenderLatencyAndViewStartFromTheSameFrame) {
  const nlohmann::json expected = fovea::pipeline::to_json(fovea::pipeline::FrameConfig{});
  // The defaults themselves, as docs/architecture.md and the help texts state them.
  EXPECT_EQ(expected["distribution"], "visual-polar");
  EXPECT_EQ(expected["budget"], 0.39);
  EXPECT_EQ(expected["stereo-share"], "gather");
  EXPECT_EQ(expected["denoiser"], "bmfr");

  const std::string dir = fovea::test::temp_dir("frame-defaults");
  const auto render = run_fovea("render --display tiny --scene cornell --frames 1 --quiet --png-every 0 --out " + dir + "/r");
  ASSERT_EQ(render.status, 0) << render.err;
  EXPECT_EQ(config_of(dir + "/r/report.json"), expected);

  const auto latency = run_fovea("latency --display tiny --scene cornell --seconds 0.1 --render-time 10ms "
                                 "--no-main-render --inject-latency none --quality-frames 0 --quiet --out " + dir + "/l");
  ASSERT_EQ(latency.status, 0) << latency.err;
  EXPECT_EQ(config_of(dir + "/l/summary.json"), expected);

  // The same names change the same thing in each.
  const auto latency2 = run_fovea("latency --display tiny --scene cornell --seconds 0.1 --render-time 10ms "
                                  "--no-main-render --inject-latency none --quality-frames 0 --quiet "
                                  "--stereo-share off --budget 0.2 --out " + dir + "/l2");
  ASSERT_EQ(latency2.status, 0) << latency2.err;
  EXPECT_EQ(config_of(dir + "/l2/summary.json")["stereo-share"], "off");
  EXPECT_EQ(config_of(dir + "/l2/summary.json")["budget"], 0.2);

  fovea::test::Xvfb x;
  if (x.running()) {
    const auto view = run_fovea("view --display tiny --scene cornell --frames 1 --gaze 0.5,0.5");
    ASSERT_EQ(view.status, 0) << view.err;
    const std::string tag = "fovea view: frame ";
    const auto at = view.err.find(tag);
    ASSERT_NE(at, std::string::npos) << view.err;
    const std::string line = view.err.substr(at + tag.size(), view.err.find('\n', at) - at - tag.size());
    EXPECT_EQ(fovea::core::parse_json(line), expected) << line;
  } else {
    std::cerr << "view not checked: Xvfb is not available\n";
  }
  fs::remove_all(dir);
}

// The option's lines in a --help text: "  --name" and the lines that continue it; empty when the
// help does not list it.
std::string help_lines(const std::string& help, const std::string& name) {
  std::istringstream in(help);
  std::string line, out;
  bool inside = false;
  while (std::getline(in, line)) {
    if (line.rfind("  --", 0) == 0) inside = line.rfind("  --" + name + " ", 0) == 0 || line == "  --" + name;
    else if (line.rfind("                        ", 0) != 0) inside = false;
    if (inside) out += line + "\n";
  }
  return out;
}

// The frame options are documented once (tools/src/render_setup.cpp): each command that
// takes them lists every one with the same text and FrameConfig's default.
TEST(FrameDefaults, RenderLatencyAndViewDescribeTheFrameOptionsAlike) {
  const auto render = run_fovea("render --help"), latency = run_fovea("latency --help"), view = run_fovea("view --help");
  ASSERT_EQ(render.status, 0) << render.err;
  ASSERT_EQ(latency.status, 0) << latency.err;
  ASSERT_EQ(view.status, 0) << view.err;
  const nlohmann::json defaults = fovea::pipeline::to_json(fovea::pipeline::FrameConfig{});
  for (const std::string& name : fovea::pipeline::frame_option_names()) {
    const std::string lines = help_lines(render.out, name);
    ASSERT_FALSE(lines.empty()) << "fovea render --help does not list --" << name;
    std::ostringstream shown;  // as the help prints a default: 0.39, 1, visual-polar
    if (defaults.at(name).is_string()) shown << defaults.at(name).get<std::string>();
    else shown << defaults.at(name).get<double>();
    EXPECT_NE(lines.find("[" + shown.str() + "]\n"), std::string::npos) << lines;
    EXPECT_EQ(help_lines(view.out, name), lines) << "fovea view --help, --" << name;
    if (name == "jitter") {  // fovea latency's --jitter is the tracker's
      EXPECT_NE(help_lines(latency.out, name).find("tracker"), std::string::npos) << latency.out;
    } else {
      EXPECT_EQ(help_lines(latency.out, name), lines) << "fovea latency --help, --" << name;
    }
  }
}

}  // namespace frame_defaults
