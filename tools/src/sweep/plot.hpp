#pragma once
// Line and scatter charts as data: what `fovea latency` and `fovea sweep report` plot,
// written to a JSON file that tools/plots/charts.py draws with matplotlib (PNG and SVG;
// docs/figures.md). The fields are those charts.py documents.
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <nlohmann/json.hpp>

namespace fovea::sweep {

struct Series {
  std::string label;  // empty: not in the legend
  std::size_t color = 0;  // index into the figure's colour cycle; series that belong together share it
  std::vector<glm::dvec2> points;  // a NaN y is a missing value: the line breaks there
  bool line = false;               // connect the points in their order
  bool markers = true;
  bool step = false;               // a step line (a CDF)
  bool gaps = false;               // break the line where x jumps far beyond its usual step
  std::vector<bool> emphasised;    // per point: ringed (e.g. a Pareto front)
  std::vector<std::string> point_labels;  // per point: text next to it (a budget, n)
  std::vector<double> vlines;      // vertical marks at these x (points unused)
  std::optional<double> hline;     // a horizontal reference line at this y
};

struct Chart {
  std::string file;  // output stem, relative to the data file: <file>.png and <file>.svg
  std::string title, x_label, y_label, note;  // note: a line under the title
  std::vector<Series> series;
};

nlohmann::json to_json(const Chart& chart);

// Writes `charts` to DIR/DATA_NAME ({"figure": "charts", ...}, atomically) and draws them
// (figures.hpp). Returns the files written: the data file and, when drawn, each PNG and SVG.
std::vector<std::string> write_charts(const std::string& dir, const std::string& data_name, const std::vector<Chart>& charts);

}  // namespace fovea::sweep
