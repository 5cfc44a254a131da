#include "latency/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace fovea::latency {

namespace {

double percentile(const std::vector<double>& sorted, double p) {
  const auto rank = static_cast<std::size_t>(std::ceil(p * double(sorted.size())));
  return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

std::string fmt(double v, int decimals = 1) {
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", std::abs(v) >= 100 ? 0 : decimals, v);
  return b;
}

// The empirical CDF of v as a step line; the legend carries n and the statistics.
sweep::Series cdf(const std::string& name, std::vector<double> v, std::size_t colour) {
  std::sort(v.begin(), v.end());
  const Distribution d = distribution(v);
  sweep::Series s;
  s.label = name + " (n=" + std::to_string(d.n) + "): median " + fmt(d.median) + ", p95 " + fmt(d.p95) + ", p99 " +
            fmt(d.p99) + ", max " + fmt(d.max) + " ms";
  s.color = colour;
  s.line = true;
  s.markers = false;
  s.step = true;
  s.points.push_back({v.front(), 0.0});
  for (std::size_t i = 0; i < v.size(); ++i) s.points.push_back({v[i], double(i + 1) / double(v.size())});
  return s;
}

}  // namespace

std::vector<double> shown_errors(const Simulation& sim) {
  std::vector<double> v;
  for (const Shown& s : sim.shown)
    if (s.error_deg) v.push_back(*s.error_deg);
  return v;
}

Distribution distribution(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  Distribution d;
  d.n = v.size();
  if (v.empty()) return d;
  std::sort(v.begin(), v.end());
  d.median = percentile(v, 0.5);
  d.p95 = percentile(v, 0.95);
  d.p99 = percentile(v, 0.99);
  d.max = v.back();
  return d;
}

nlohmann::json to_json(const Distribution& d) {
  // No values: no statistic (null), never a 0 that reads as a measured zero latency.
  const auto stat = [&](double v) { return d.n > 0 ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return {{"n", d.n}, {"median", stat(d.median)}, {"p95", stat(d.p95)}, {"p99", stat(d.p99)}, {"max", stat(d.max)}};
}

Latencies latencies(const std::vector<xrcommon::TimingRecord>& records) {
  Latencies l;
  for (const auto& r : records) {
    std::optional<core::TimeNs> photon = r.vsync_ns;
    if (r.photon_ns) photon = (*r.photon_ns)[0].mid;
    if (r.gaze_sample_ns && r.gaze_receive_ns)
      l.tracker_delay_ms.push_back(core::ns_to_ms(*r.gaze_receive_ns - *r.gaze_sample_ns));
    if (r.gaze_sample_ns && photon) l.gaze_to_photon_ms.push_back(core::ns_to_ms(*photon - *r.gaze_sample_ns));
    if (r.head_pose_ns && photon) l.motion_to_photon_ms.push_back(core::ns_to_ms(*photon - *r.head_pose_ns));
  }
  return l;
}

nlohmann::json error_summary(const std::vector<double>& error_deg) {
  nlohmann::json j = to_json(distribution(error_deg));
  double sum = 0;
  for (double e : error_deg) sum += e;
  j["mean"] = error_deg.empty() ? nlohmann::json(nullptr) : nlohmann::json(sum / double(error_deg.size()));
  for (double th : {1.0, 2.0, 5.0}) {
    const auto above = std::count_if(error_deg.begin(), error_deg.end(), [&](double e) { return e > th; });
    j["above_" + fmt(th, 0) + "deg"] =
        error_deg.empty() ? nlohmann::json(nullptr) : nlohmann::json(double(above) / double(error_deg.size()));
  }
  return j;
}

nlohmann::json summarize(const std::vector<xrcommon::TimingRecord>& records, const Simulation* sim) {
  nlohmann::json j;
  j["frames"] = records.size();
  std::int64_t missed = 0, missed_frames = 0;
  for (const auto& r : records) {
    missed += r.missed_vsyncs;
    missed_frames += r.missed_vsyncs > 0;
  }
  j["missed_vsyncs"] = missed;
  j["frames_missing_a_vsync"] = missed_frames;
  const Latencies l = latencies(records);
  j["tracker_delay_ms"] = to_json(distribution(l.tracker_delay_ms));
  j["gaze_to_photon_ms"] = to_json(distribution(l.gaze_to_photon_ms));
  j["motion_to_photon_ms"] = to_json(distribution(l.motion_to_photon_ms));
  std::map<std::string, std::vector<double>> cpu, gpu;
  for (const auto& r : records) {
    for (const auto& [k, v] : r.cpu_ms) cpu[k].push_back(v);
    for (const auto& [k, v] : r.gpu_ms) gpu[k].push_back(v);
  }
  for (const auto& [k, v] : cpu) j["stages"]["cpu_ms"][k] = to_json(distribution(v));
  for (const auto& [k, v] : gpu) j["stages"]["gpu_ms"][k] = to_json(distribution(v));
  if (sim) {
    // What the eye saw: every vsync, repeated frames included.
    std::size_t repeats = 0;
    for (std::size_t i = 1; i < sim->shown.size(); ++i) repeats += sim->shown[i].frame == sim->shown[i - 1].frame;
    j["panel"] = {{"vsyncs", sim->shown.size()}, {"repeated_vsyncs", repeats}};
    j["foveal_error_deg"] = error_summary(shown_errors(*sim));
    j["foveal_error_deg"]["over"] = "vsyncs";
    std::size_t big = 0;
    for (const Saccade& s : sim->saccades) big += s.amplitude_deg >= 2.0;
    j["saccades"] = {{"detected", sim->saccades.size()}, {"at_least_2deg", big}};
    j["recovery_ms"] = to_json(distribution(recovery_ms(*sim)));
    j["post_saccade_error_deg"] = error_summary(post_saccade_errors(*sim));
    j["post_saccade_error_deg"]["over"] = "vsyncs within 150 ms after each saccade of at least 2 deg";
  } else {
    std::vector<double> e;
    for (const auto& r : records)
      if (auto d = r.foveal_error_deg()) e.push_back(*d);
    if (!e.empty()) {
      j["foveal_error_deg"] = error_summary(e);
      j["foveal_error_deg"]["over"] = "frames";
    }
  }
  return j;
}

std::vector<sweep::Chart> plots(const std::vector<xrcommon::TimingRecord>& records, const Simulation* sim,
                                const std::string& note) {
  std::vector<sweep::Chart> charts;
  const Latencies l = latencies(records);
  sweep::Chart c;
  c.file = "latency";
  c.title = "Latency distributions (CDF)";
  c.note = note;
  c.x_label = "latency (ms)";
  c.y_label = "fraction of frames";
  std::size_t colour = 0;
  for (auto [name, v] : {std::pair{"tracker delay", &l.tracker_delay_ms}, {"gaze-to-photon", &l.gaze_to_photon_ms},
                         {"motion-to-photon", &l.motion_to_photon_ms}})
    if (!v->empty()) c.series.push_back(cdf(name, *v, colour++));
  if (!c.series.empty()) charts.push_back(c);

  std::map<std::string, std::vector<double>> stages;
  for (const auto& r : records) {
    for (const auto& [k, v] : r.cpu_ms) stages["CPU " + k].push_back(v);
    for (const auto& [k, v] : r.gpu_ms) stages["GPU " + k].push_back(v);
  }
  sweep::Chart st;
  st.file = "stages";
  st.title = "Per-stage time (CDF)";
  st.note = note;
  st.x_label = "time per frame (ms)";
  st.y_label = "fraction of frames";
  colour = 0;
  for (const auto& [k, v] : stages) st.series.push_back(cdf(k, v, colour++));
  if (!st.series.empty()) charts.push_back(st);

  if (sim && !sim->shown.empty()) {
    sweep::Chart e;
    e.file = "foveal_error";
    e.title = "Foveal error at photon time";
    e.note = note;
    e.x_label = "time (s)";
    e.y_label = "angle true gaze to fovea (deg)";
    // Vsyncs without a true eye are missing values: the line breaks there, and at gaps in time.
    sweep::Series err{"foveal error (panel, every vsync with a true eye)", 0, {}, true, false};
    err.gaps = true;
    for (const Shown& s : sim->shown)
      err.points.push_back({double(s.photon_ns) * 1e-9, s.error_deg ? *s.error_deg : std::nan("")});
    e.series.push_back(err);
    sweep::Series onsets{"saccade onset (I-VT on the true eye)", 3, {}, false, false};
    for (const Saccade& s : sim->saccades) onsets.vlines.push_back(double(s.onset_ns) * 1e-9);
    if (!onsets.vlines.empty()) e.series.push_back(onsets);
    sweep::Series two{"2 deg (recovered below)", 2, {}, false, false};
    two.hline = 2.0;
    e.series.push_back(two);
    charts.push_back(e);
  }
  return charts;
}

std::vector<sweep::Chart> sweep_plots(const std::vector<SweepPoint>& points, const std::string& note) {
  std::vector<sweep::Chart> charts;
  sweep::Chart c;
  c.file = "sweep_error";
  c.title = "Injected latency vs foveal error";
  c.note = note + "; n: vsyncs with a true eye";
  c.x_label = "injected latency (ms)";
  c.y_label = "foveal error at photon time (deg)";
  sweep::Series med{"median", 0, {}, true, true}, p95{"p95", 1, {}, true, true};
  for (const SweepPoint& p : points) {
    if (p.error["median"].is_null()) continue;  // no shown frame had a true eye
    med.points.push_back({p.inject_ms, p.error["median"].get<double>()});
    med.point_labels.push_back("n=" + std::to_string(p.error["n"].get<std::size_t>()));
    p95.points.push_back({p.inject_ms, p.error["p95"].get<double>()});
  }
  c.series = {med, p95};
  charts.push_back(c);
  // Quality is a mean over few frames after few saccades: each point carries its n.
  sweep::Series ps{"", 0, {}, true, true}, fl{"", 1, {}, true, true};
  for (const SweepPoint& p : points) {
    if (!p.fovea_psnr_db) continue;
    const std::string n = std::to_string(p.quality_frames) + " frames, " + std::to_string(p.quality_saccades) + " sacc.";
    ps.points.push_back({p.inject_ms, *p.fovea_psnr_db});
    fl.points.push_back({p.inject_ms, *p.fovea_hdr_flip});
    ps.point_labels.push_back(n);
    fl.point_labels.push_back(n);
    ps.label = "PSNR, " + fmt(p.quality_radius_deg) + " deg around the true gaze";
    fl.label = "HDR-FLIP, " + fmt(p.quality_radius_deg) + " deg around the true gaze";
  }
  if (!ps.points.empty()) {
    sweep::Chart q;
    q.title = "Injected latency vs quality where the user looks, after saccades";
    q.note = note;
    q.x_label = "injected latency (ms)";
    q.file = "sweep_quality";
    q.y_label = "fovea PSNR, tone-mapped (dB)";
    q.series = {ps};
    charts.push_back(q);
    q.file = "sweep_flip";
    q.y_label = "fovea HDR-FLIP (lower is better)";
    q.series = {fl};
    charts.push_back(q);
  }
  return charts;
}

}  // namespace fovea::latency
