#pragma once
// Merges a sweep's results (jobs/<id>/report.json) into results.csv and results.json and
// draws the plots: quality against time per frame with the Pareto front per group, quality
// against budget, per-band curves, latency against quality. Metric names: docs/sweep.md.
#include <map>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <nlohmann/json.hpp>

#include "sweep/plan.hpp"

namespace fovea::sweep {

struct BandValue {
  double e_min = 0, e_max = 0, value = 0;
};

// Every finite number of a render report under a dotted name ("gpu_ms.total",
// "summary.left.psnr"), "config" excepted, plus the mean over both eyes of each per-eye
// number under its name without "summary.<eye>." ("psnr").
std::map<std::string, double> flatten_metrics(const nlohmann::json& report);
// A `fovea latency` summary: every finite number by its dotted name like a render report
// ("gaze_to_photon_ms.median", "foveal_error_deg.above_2deg"), plus the numbers of the
// fovea_quality object of its injected-latency point at 0 ms, the job's own latency
// ("fovea_quality.psnr_db", "fovea_quality.ldr_flip"), unless the summary has its own.
std::map<std::string, double> latency_metrics(const nlohmann::json& summary);
// Per-eye arrays of {e_min, e_max, <value>...}: "<array>.<value>" -> bands, averaged over eyes.
std::map<std::string, std::vector<BandValue>> band_metrics(const nlohmann::json& report);

// Points (cost, quality): true for those no other point beats, i.e. no point with cost <= and
// quality at least as good with one of them strictly better. Non-finite points are never on it.
std::vector<bool> pareto_front(const std::vector<glm::dvec2>& points, bool higher_is_better);
// Direction of a metric by its name: errors, FLIP, MSE and times are lower-is-better.
bool lower_is_better_by_name(const std::string& metric);

struct ReportOptions {
  std::string dir;  // results directory
  std::string out;  // where results.csv, results.json and the PNGs go
  // Non-empty: also a Markdown page there (tables and the PNGs, linked relative to it).
  std::string markdown;
  std::string command;  // how the page is regenerated, quoted in its header
};

struct ReportSummary {
  std::size_t done = 0, failed = 0, missing = 0;
  std::vector<std::string> files;  // written, relative to out
};

ReportSummary write_report(const Plan& plan, const ReportOptions& options);

}  // namespace fovea::sweep
