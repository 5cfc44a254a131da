// Figures (docs/figures.md): every plotting command writes its data and draws it with
// matplotlib as PNG and SVG; without Python it still succeeds and says how to draw them.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "fovea/core/json.hpp"
#include "sweep/plot.hpp"

namespace fs = std::filesystem;
using fovea::test::FiguresAsData;
using fovea::test::kFiguresDrawn;
using fovea::test::PythonOverride;
using fovea::test::read_text;
using fovea::test::run_fovea;
using fovea::test::temp_dir;

namespace {

std::string shipped_gaze() {
  const char* s = std::getenv("FOVEA_SOURCE_DIR");
  return std::string(s ? s : ".") + "/data/gaze/default.csv";
}
// A cheap latency run: virtual time, fixed render cost, no frame rendered.
const std::string kLatency =
    "latency --display tiny --render-time 10ms --no-main-render --seconds 0.6 --quality-frames 0 "
    "--inject-latency 0,50 --quiet --out ";

bool is_png(const std::string& path) { return read_text(path).rfind("\x89PNG\r\n\x1a\n", 0) == 0; }
bool is_svg(const std::string& path) {
  const std::string s = read_text(path);
  return s.find("<svg") != std::string::npos && s.find("</svg>") != std::string::npos;
}

TEST(Figures, GazePlotWritesPngSvgAndData) {
  const FiguresAsData figures;
  const std::string dir = temp_dir("fig-gaze");
  const auto r = run_fovea("gaze plot " + shipped_gaze() + " " + dir + "/g.png");
  ASSERT_EQ(r.status, 0) << r.err;
  if (kFiguresDrawn) {
    EXPECT_TRUE(is_png(dir + "/g.png"));
    EXPECT_TRUE(is_svg(dir + "/g.svg"));
    const std::string svg = read_text(dir + "/g.svg");
    EXPECT_NE(svg.find("screen x (px)"), std::string::npos) << "units on the axes";
    EXPECT_NE(svg.find("time from the first sample (s)"), std::string::npos);
  }
  const auto j = fovea::core::parse_json(read_text(dir + "/g.json"));
  EXPECT_EQ(j["figure"], "gaze");
  EXPECT_EQ(j["file"], "g");
  ASSERT_GT(j["t"].size(), 500u);  // 5 s at 120 Hz
  EXPECT_EQ(j["h"].size(), j["t"].size());
  EXPECT_GT(j["saccades"].size(), 5u);
  EXPECT_GT(j["sample_period_s"].get<double>(), 0);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
  fs::remove_all(dir);
}

TEST(Figures, GazePlotBreaksLinesAtGaps) {
  if (!kFiguresDrawn) GTEST_SKIP() << "what matplotlib draws is checked in the Release build";
  // 0.8 s at 250 Hz, a 2-hour gap, 0.8 s more: two line pieces, not one line across the gap.
  const std::string dir = temp_dir("fig-gap");
  std::string csv = "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n";
  for (long long part : {0LL, 7200000000000LL})
    for (int i = 0; i < 200; ++i)
      csv += std::to_string(part + i * 4000000LL) + ",C," + std::to_string(0.1 * std::sin(i / 20.0)) + ",0,-1,1,1\n";
  FILE* f = std::fopen((dir + "/gap.csv").c_str(), "w");
  std::fputs(csv.c_str(), f);
  std::fclose(f);
  const auto r = run_fovea("gaze plot " + dir + "/gap.csv " + dir + "/g.png");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = fovea::core::parse_json(read_text(dir + "/g.json"));
  EXPECT_NEAR(j["sample_period_s"].get<double>(), 0.004, 1e-9);
  const std::string svg = read_text(dir + "/g.svg");
  const auto at = svg.find("id=\"gaze-h\"");
  ASSERT_NE(at, std::string::npos);
  const auto d = svg.find(" d=\"", at);
  ASSERT_NE(d, std::string::npos);
  const std::string path = svg.substr(d + 4, svg.find('"', d + 4) - d - 4);
  EXPECT_EQ(std::count(path.begin(), path.end(), 'M'), 2) << path;  // one move per piece
  fs::remove_all(dir);
}

TEST(Figures, LatencyChartsComeFromFiguresJson) {
  const FiguresAsData figures;
  const std::string dir = temp_dir("fig-latency");
  const auto r = run_fovea(kLatency + dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = fovea::core::parse_json(read_text(dir + "/figures.json"));
  EXPECT_EQ(j["figure"], "charts");
  std::vector<std::string> files;
  for (const auto& c : j["charts"]) files.push_back(c["file"]);
  EXPECT_EQ(files, (std::vector<std::string>{"latency", "foveal_error", "sweep_error"}));
  for (const auto& f : kFiguresDrawn ? files : std::vector<std::string>{}) {
    EXPECT_TRUE(is_png(dir + "/" + f + ".png")) << f;
    EXPECT_TRUE(is_svg(dir + "/" + f + ".svg")) << f;
  }
  // The CDF legends carry n; each sweep point its n; the error over time breaks at gaps.
  EXPECT_NE(j["charts"][0]["series"][0]["label"].get<std::string>().find("(n="), std::string::npos);
  EXPECT_EQ(j["charts"][1]["series"][0]["gaps"], true);
  EXPECT_EQ(j["charts"][2]["series"][0]["point_labels"].size(), 2u);
  const auto summary = fovea::core::parse_json(r.out);
  EXPECT_EQ(summary["plots"][0], "figures.json");
  if (kFiguresDrawn) {  // the files drawn; without Python only the data
    EXPECT_NE(std::find(summary["plots"].begin(), summary["plots"].end(), "latency.svg"), summary["plots"].end());
  }
  fs::remove_all(dir);
}

TEST(Figures, ChartsMissingValuesAreNullNeverNaN) {
  fovea::sweep::Chart c;
  c.file = "x";
  fovea::sweep::Series s{"error", 0, {{0, 1}, {1, std::nan("")}, {2, 3}}, true, false};
  s.vlines = {0.5};
  c.series.push_back(s);
  const nlohmann::json j = fovea::sweep::to_json(c);
  EXPECT_TRUE(j["series"][0]["points"][1][1].is_null());
  EXPECT_EQ(j["series"][0]["vlines"], nlohmann::json({0.5}));
  EXPECT_EQ(j.dump().find("NaN"), std::string::npos);
}

TEST(Figures, WithoutPythonTheDataIsWrittenAndANoteSaysHow) {
  const std::string dir = temp_dir("fig-nopython");
  {
    const PythonOverride none("/nonexistent/python3");
    const auto g = run_fovea("gaze plot " + shipped_gaze() + " " + dir + "/g.png");
    ASSERT_EQ(g.status, 0) << g.err;
    EXPECT_TRUE(fs::exists(dir + "/g.json"));
    EXPECT_FALSE(fs::exists(dir + "/g.png"));
    EXPECT_NE(g.err.find("tools/plots/gaze.py"), std::string::npos) << g.err;
    EXPECT_NE(g.err.find("/nonexistent/python3"), std::string::npos) << g.err;
    EXPECT_NE(g.err.find("fovea plot " + dir + "/g.json"), std::string::npos) << g.err;

    const auto d = run_fovea("density --display tiny --out " + dir + "/d.png");
    ASSERT_EQ(d.status, 0) << d.err;
    EXPECT_TRUE(fs::exists(dir + "/d.json") && fs::exists(dir + "/d.npy"));
    EXPECT_NE(d.err.find("fovea plot " + dir + "/d.json"), std::string::npos) << d.err;

    const auto l = run_fovea(kLatency + dir + "/lat");
    ASSERT_EQ(l.status, 0) << l.err;
    EXPECT_TRUE(fs::exists(dir + "/lat/figures.json"));
    EXPECT_FALSE(fs::exists(dir + "/lat/latency.png"));
    EXPECT_EQ(fovea::core::parse_json(l.out)["plots"], nlohmann::json({"figures.json"}));
    EXPECT_NE(l.err.find("fovea plot " + dir + "/lat/figures.json"), std::string::npos) << l.err;

    // `fovea plot` itself, without Python: exit 1 (not a bad input), nothing drawn.
    EXPECT_EQ(run_fovea("plot " + dir + "/g.json").status, 1);
  }
  // The command the note gives draws them once Python is there.
  for (const char* data : {"g.json", "d.json", "lat/figures.json"}) {
    const auto p = run_fovea("plot " + dir + "/" + data);
    EXPECT_EQ(p.status, 0) << data << ": " << p.err;
  }
  EXPECT_TRUE(is_png(dir + "/g.png") && is_svg(dir + "/g.svg"));
  EXPECT_TRUE(is_png(dir + "/d.png") && is_svg(dir + "/d.svg"));
  EXPECT_TRUE(is_png(dir + "/lat/sweep_error.png") && is_svg(dir + "/lat/sweep_error.svg"));
  fs::remove_all(dir);
}

TEST(Figures, RedrawIsByteIdentical) {
  if (!kFiguresDrawn) GTEST_SKIP() << "what matplotlib draws is checked in the Release build";
  const std::string dir = temp_dir("fig-repro");
  ASSERT_EQ(run_fovea("density --display tiny --out " + dir + "/d.png").status, 0);
  const std::string png = read_text(dir + "/d.png"), svg = read_text(dir + "/d.svg");
  ASSERT_EQ(run_fovea("plot " + dir + "/d.json").status, 0);
  EXPECT_EQ(read_text(dir + "/d.png"), png);
  EXPECT_EQ(read_text(dir + "/d.svg"), svg);
  fs::remove_all(dir);
}

TEST(Figures, PlotRefusesWhatIsNotFigureData) {
  const std::string dir = temp_dir("fig-bad");
  for (const auto& [name, text] : {std::pair{"a.json", "{\"x\": 1}"}, {"b.json", "not json"}, {"c.json", "{\"figure\": \"pie\"}"}}) {
    const std::string path = dir + "/" + name;
    FILE* f = std::fopen(path.c_str(), "w");
    std::fputs(text, f);
    std::fclose(f);
    const auto r = run_fovea("plot " + path);
    EXPECT_EQ(r.status, 2) << name;
    EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
  }
  EXPECT_EQ(run_fovea("plot " + dir + "/missing.json").status, 2);
  fs::remove_all(dir);
}

}  // namespace
