#include "sweep/plot.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>

#include "figures.hpp"
#include "fovea/core/image.hpp"

namespace fovea::sweep {
namespace {

// JSON has no NaN or Inf: a missing value is null.
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

nlohmann::json to_json(const Chart& c) {
  nlohmann::json series = nlohmann::json::array();
  for (const Series& s : c.series) {
    nlohmann::json j = {{"label", s.label}, {"color", s.color}, {"line", s.line}, {"markers", s.markers}};
    nlohmann::json pts = nlohmann::json::array();
    for (const auto& p : s.points) pts.push_back({number(p.x), number(p.y)});
    j["points"] = pts;
    if (s.step) j["step"] = true;
    if (s.gaps) j["gaps"] = true;
    if (!s.emphasised.empty()) j["emphasised"] = s.emphasised;
    if (!s.point_labels.empty()) j["point_labels"] = s.point_labels;
    if (!s.vlines.empty()) j["vlines"] = s.vlines;
    if (s.hline) j["hline"] = number(*s.hline);
    series.push_back(j);
  }
  return {{"file", c.file}, {"title", c.title}, {"note", c.note}, {"x_label", c.x_label}, {"y_label", c.y_label},
          {"series", series}};
}

std::vector<std::string> write_charts(const std::string& dir, const std::string& data_name, const std::vector<Chart>& charts) {
  if (charts.empty()) return {};
  nlohmann::json j = {{"figure", "charts"}, {"charts", nlohmann::json::array()}};
  for (const Chart& c : charts) j["charts"].push_back(to_json(c));
  const std::string path = (std::filesystem::path(dir) / data_name).string();
  core::write_file_atomic(path, j.dump(1) + "\n");
  std::vector<std::string> written = {data_name};
  if (tools::draw_figures("charts", path, std::cerr))
    for (const Chart& c : charts) written.insert(written.end(), {c.file + ".png", c.file + ".svg"});
  return written;
}

}  // namespace fovea::sweep
