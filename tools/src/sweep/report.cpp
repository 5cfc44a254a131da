#include "sweep/report.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>

#include "fovea/core/duration.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/input_limits.hpp"
#include "fovea/core/json.hpp"
#include "sweep/plot.hpp"

namespace fovea::sweep {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

bool is_band_array(const json& v) {
  return v.is_array() && !v.empty() && v[0].is_object() && v[0].contains("e_min") && v[0].contains("e_max");
}

void flatten(const json& j, const std::string& prefix, std::map<std::string, double>& out) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string name = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it->is_object()) flatten(*it, name, out);
    else if (it->is_number() && std::isfinite(it->get<double>())) out[name] = it->get<double>();
  }
}

std::string cell(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string csv_escape(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string o = "\"";
  for (char c : s) o += c == '"' ? std::string("\"\"") : std::string(1, c);
  return o + "\"";
}

std::string file_stem(const std::string& metric) {
  std::string s = metric;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

// A metric's key in words, e.g. "fovea_hdr_flip" -> "fovea HDR-FLIP", "cpu_ms.total" ->
// "CPU time: total".
std::string human_name(const std::string& m) {
  static const std::pair<const char*, const char*> kWords[] = {
      {"gaze_to_photon_ms", "gaze-to-photon latency"}, {"foveal_error_deg", "foveal error"},
      {"fovea_quality", "fovea quality after saccades"}, {"hdr_flip", "HDR-FLIP"}, {"ldr_flip", "LDR-FLIP"},
      {"psnr_db", "PSNR"}, {"psnr", "PSNR"}, {"ssim", "SSIM"}, {"rel_mse", "relative MSE"}, {"cpu_ms", "CPU time"},
      {"gpu_ms", "GPU time"}, {"wall_seconds", "wall time"}, {"above_", "share above "}};
  std::string s = m;
  for (const auto& [key, words] : kWords)
    for (auto at = s.find(key); at != std::string::npos; at = s.find(key, at + std::string_view(words).size()))
      s.replace(at, std::string_view(key).size(), words);
  std::string out;
  for (char c : s) out += c == '_' ? std::string(" ") : c == '.' ? std::string(": ") : std::string(1, c);
  return out;
}

// Axis label: the metric in words with the unit its key implies.
std::string axis_label(const std::string& m) {
  const std::string h = human_name(m);
  if (m.find("psnr") != std::string::npos) return h + " (dB)";
  if (m.find(".above_") != std::string::npos) return h + " (fraction of vsyncs)";
  if (m.find("_deg") != std::string::npos) return h + " (deg)";
  if (m.find("_ms") != std::string::npos || m.rfind("ms", m.size() - 2) == m.size() - 2) return h + " (ms)";
  if (m.find("seconds") != std::string::npos) return h + " (s)";
  if (m.find("flip") != std::string::npos) return h + " (lower is better)";
  return h;
}

// fovea latency's summary: the share of vsyncs whose foveal error exceeds 2°, and the
// prefix of the fovea quality its sweep point at the job's own latency reports.
constexpr const char* kFovealErrorShare = "foveal_error_deg.above_2deg";
constexpr const char* kLatencyQuality = "fovea_quality.";

struct Row {
  std::string id, status;
  json settings;
  std::string device;  // the Vulkan device and driver of its report
  std::map<std::string, double> metrics;
  std::map<std::string, std::vector<BandValue>> bands;
  std::vector<std::string> members;  // the jobs a row of repeated runs stands for (report.repeat)
};

std::string setting_text(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }
std::string group_text(const Row& r, const std::string& group) {
  return r.settings.contains(group) ? setting_text(r.settings[group]) : "";
}

// report.speedup: one group's whole-frame speed-up over another's per section, at equal quality
// or, with `at`, at the listed budgets (a sweep that measures time only, without references).
struct SpeedUp {
  std::string of, over;
  std::vector<std::string> quality;  // as good in each; empty = the first quality metric
  double tolerance = 0;              // relative: "as good" allows this much worse
  std::vector<double> at;            // the `of` jobs' budgets compared; empty: at equal quality
};

struct Config {
  std::vector<std::string> quality, bands, latency_quality;
  std::string time = "gpu_ms.total", group = "distribution", budget = "budget", latency, latency_group;
  std::string repeat;  // the setting whose values are repeated runs of one job (e.g. "seed")
  std::vector<std::string> section = {"scene"};  // as configured
  std::vector<std::string> section_keys;          // of those, the ones whose value differs between render jobs
  std::vector<SpeedUp> speedups;  // one table each
  std::set<std::string> lower, higher;
  bool lower_better(const std::string& m) const {
    if (lower.count(m)) return true;
    if (higher.count(m)) return false;
    return lower_is_better_by_name(m);
  }
};

// The section a render job's tables and plots belong to: its values of the section settings
// ("default", or "default/fove0" when both the scene and the display vary), and its title
// ("scene default, display fove0").
std::string section_of(const Row& r, const Config& c) {
  std::string s;
  for (std::size_t i = 0; i < c.section_keys.size(); ++i)
    s += (i ? "/" : "") + (r.settings.contains(c.section_keys[i]) ? setting_text(r.settings[c.section_keys[i]]) : "");
  return s;
}
std::string section_title(const Row& r, const Config& c) {
  std::string s;
  for (const auto& k : c.section_keys)
    s += (s.empty() ? "" : ", ") + k + " " + (r.settings.contains(k) ? setting_text(r.settings[k]) : "–");
  return s;
}
struct Section {
  std::string id, title;
};
// A heading's anchor as Markdown renderers make it: lower case, spaces to hyphens, other
// punctuation dropped.
std::string anchor_of(const std::string& heading) {
  std::string a;
  for (unsigned char c : heading)
    if (std::isalnum(c)) a += char(std::tolower(c));
    else if (c == ' ' || c == '-') a += '-';
    else if (c == '_' || c >= 0x80) a += char(c);
  return a;
}
// The plots of latency jobs: their own section of the page, after the render sections.
const std::string kLatencySection = "\n latency";

Config read_config(const json& r, const std::vector<Row>& rows) {
  Config c;
  std::set<std::string> present;
  for (const auto& row : rows)
    for (const auto& [k, v] : row.metrics) present.insert(k);
  auto strings = [&](const char* key) {
    std::vector<std::string> v;
    if (!r.contains(key)) return v;
    const json& x = r[key];
    if (x.is_string()) v.push_back(x);
    else if (x.is_array())
      for (const auto& e : x) {
        if (!e.is_string()) throw core::InputError(std::string("report.") + key + ": expected metric names");
        v.push_back(e);
      }
    else throw core::InputError(std::string("report.") + key + ": expected a name or a list of names");
    return v;
  };
  c.quality = strings("quality");
  if (c.quality.empty()) {
    // Every both-eye quality metric the renders report, the fovea's first: new metrics in
    // report.json (FLIP, tone-mapped PSNR, ...) are plotted without a change here.
    for (const auto& m : present)
      if (m.find('.') == std::string::npos)
        for (const char* kind : {"psnr", "ssim", "flip", "mse"})
          if (m.find(kind) != std::string::npos) {
            c.quality.push_back(m);
            break;
          }
    std::stable_partition(c.quality.begin(), c.quality.end(), [](const std::string& m) { return m.rfind("fovea_", 0) == 0; });
  }
  if (c.quality.empty() && present.count("temporal_error")) c.quality.push_back("temporal_error");
  if (auto t = strings("time"); !t.empty()) c.time = t[0];
  if (auto g = strings("group"); !g.empty()) c.group = g[0];
  if (auto b = strings("budget"); !b.empty()) c.budget = b[0];
  if (auto s = strings("section"); !s.empty()) c.section = s;
  if (auto s = strings("repeat"); !s.empty()) c.repeat = s[0];
  for (const auto& k : c.section) {
    std::set<std::string> values;
    for (const auto& row : rows)
      if (job_command(row.settings) == "render")
        values.insert(row.settings.contains(k) ? setting_text(row.settings[k]) : "");
    if (values.size() > 1) c.section_keys.push_back(k);
  }
  if (c.section_keys.empty()) c.section_keys.push_back(c.section[0]);
  const json speedups = !r.contains("speedup") ? json::array() : r["speedup"].is_array() ? r["speedup"]
                                                                                          : json::array({r["speedup"]});
  for (const json& x : speedups) {
    const auto bad = [](const std::string& what) { return core::InputError("report.speedup: " + what); };
    if (!x.is_object())
      throw bad("expected an object {\"of\": GROUP, \"over\": GROUP, \"quality\": METRIC or [METRIC, ...], "
                "\"tolerance\": N} or {\"of\": GROUP, \"over\": GROUP, \"at\": [BUDGET, ...]}, or a list of them");
    SpeedUp s;
    for (const auto& [k, v] : x.items()) {
      if (k == "of" || k == "over") {
        if (!v.is_string() || v.get<std::string>().empty()) throw bad(k + ": expected a non-empty name");
        (k == "of" ? s.of : s.over) = v.get<std::string>();
      } else if (k == "quality") {
        for (const json& m : v.is_array() ? v : json::array({v})) {
          if (!m.is_string() || m.get<std::string>().empty())
            throw bad("quality: expected a metric or a list of metrics");
          s.quality.push_back(m.get<std::string>());
        }
        if (s.quality.empty()) throw bad("quality: expected a metric or a list of metrics");
      } else if (k == "tolerance") {
        if (!v.is_number() || !(v.get<double>() >= 0 && v.get<double>() < 1))
          throw bad("tolerance: expected a number in [0, 1)");
        s.tolerance = v.get<double>();
      } else if (k == "at") {
        for (const json& b : v.is_array() ? v : json::array({v})) {
          if (!b.is_number()) throw bad("at: expected a budget or a list of budgets");
          s.at.push_back(b.get<double>());
        }
        if (s.at.empty()) throw bad("at: expected a budget or a list of budgets");
      } else {
        throw bad("unknown key \"" + k + "\" (of, over, quality, tolerance, at)");
      }
    }
    if (s.of.empty() || s.over.empty()) throw bad("\"of\" and \"over\" are required");
    c.speedups.push_back(s);
  }
  c.bands = strings("bands");
  if (auto l = strings("latency"); !l.empty()) c.latency = l[0];
  else if (present.count("gaze_to_photon_ms.median")) c.latency = "gaze_to_photon_ms.median";  // fovea latency's
  else
    for (const auto& m : present)
      if (m.find("photon") != std::string::npos || m.find("latency") != std::string::npos) {
        c.latency = m;
        break;
      }
  // Latency plots: y metrics and legend, from the rows that carry the latency metric.
  std::set<std::string> with_latency;
  bool predict = false;
  for (const auto& row : rows)
    if (row.metrics.count(c.latency)) {
      for (const auto& [k, v] : row.metrics) with_latency.insert(k);
      predict = predict || row.settings.contains("predict");
    }
  c.latency_quality = strings("latency_quality");
  if (c.latency_quality.empty()) {
    if (with_latency.count(kFovealErrorShare)) c.latency_quality.push_back(kFovealErrorShare);
    for (const auto& m : with_latency)
      if (m.rfind(kLatencyQuality, 0) == 0 && (m.find("flip") != std::string::npos || m.find("psnr") != std::string::npos))
        c.latency_quality.push_back(m);
    for (const auto& q : c.quality)
      if (with_latency.count(q)) c.latency_quality.push_back(q);
  }
  if (auto g = strings("latency_group"); !g.empty()) c.latency_group = g[0];
  else c.latency_group = predict ? "predict" : c.group;
  for (const auto& m : strings("lower_is_better")) c.lower.insert(m);
  for (const auto& m : strings("higher_is_better")) c.higher.insert(m);
  return c;
}

// Settings keys whose value differs between jobs: what distinguishes them in a legend.
std::vector<std::string> varied_keys(const std::vector<Row>& rows) {
  std::map<std::string, std::set<std::string>> values;
  for (const auto& r : rows)
    for (auto it = r.settings.begin(); it != r.settings.end(); ++it) values[it.key()].insert(it->dump());
  std::vector<std::string> out;
  for (const auto& [k, v] : values)
    if (v.size() > 1 || std::any_of(rows.begin(), rows.end(), [&](const Row& r) { return !r.settings.contains(k); }))
      out.push_back(k);
  return out;
}

}  // namespace

std::map<std::string, double> flatten_metrics(const json& report) {
  std::map<std::string, double> out;
  json j = report;
  if (j.is_object()) j.erase("config");
  flatten(j, "", out);
  if (j.contains("summary") && j["summary"].contains("left") && j["summary"].contains("right")) {
    std::map<std::string, double> l, r;
    flatten(j["summary"]["left"], "", l);
    flatten(j["summary"]["right"], "", r);
    for (const auto& [k, v] : l)
      if (r.count(k)) out[k] = 0.5 * (v + r[k]);
  }
  return out;
}

std::map<std::string, double> latency_metrics(const json& summary) {
  std::map<std::string, double> out = flatten_metrics(summary);
  // Read by key name only: the summary may gain keys; a missing one leaves its metric out.
  if (!summary.is_object() || !summary.contains("sweep") || !summary["sweep"].is_array()) return out;
  for (const json& point : summary["sweep"]) {
    if (!point.is_object() || !point.contains("inject_ms") || !point["inject_ms"].is_number() ||
        point["inject_ms"].get<double>() != 0 || !point.contains("fovea_quality") || !point["fovea_quality"].is_object())
      continue;
    std::map<std::string, double> q;
    flatten(point["fovea_quality"], "", q);
    for (const auto& [k, v] : q) out.emplace(kLatencyQuality + k, v);  // emplace: the summary's own wins
    break;
  }
  return out;
}

std::map<std::string, std::vector<BandValue>> band_metrics(const json& report) {
  std::map<std::string, std::vector<BandValue>> out;
  if (!report.contains("summary") || !report["summary"].is_object()) return out;
  std::map<std::string, std::vector<std::vector<BandValue>>> per_eye;
  for (const auto& eye : report["summary"]) {
    if (!eye.is_object()) continue;
    for (auto it = eye.begin(); it != eye.end(); ++it) {
      if (!is_band_array(*it)) continue;
      std::map<std::string, std::vector<BandValue>> series;
      for (const auto& b : *it)
        for (auto f = b.begin(); f != b.end(); ++f)
          if (f.key() != "e_min" && f.key() != "e_max" && f.key() != "pixels" && f->is_number() &&
              std::isfinite(f->get<double>()))
            series[it.key() + "." + f.key()].push_back({b["e_min"].get<double>(), b["e_max"].get<double>(), f->get<double>()});
      for (auto& [k, v] : series) per_eye[k].push_back(std::move(v));
    }
  }
  for (auto& [name, eyes] : per_eye) {
    // Mean over the eyes of the bands both have (same e_min).
    std::vector<BandValue> merged;
    for (const BandValue& b : eyes[0]) {
      double sum = b.value;
      std::size_t n = 1;
      for (std::size_t e = 1; e < eyes.size(); ++e)
        for (const BandValue& o : eyes[e])
          if (std::abs(o.e_min - b.e_min) < 1e-9) sum += o.value, ++n;
      if (n == eyes.size()) merged.push_back({b.e_min, b.e_max, sum / double(n)});
    }
    out[name] = merged;
  }
  return out;
}

bool lower_is_better_by_name(const std::string& m) {
  for (const char* s : {"flip", "error", "mse", "_ms", "gpu_ms", "cpu_ms", "seconds", "latency", "photon"})
    if (m.find(s) != std::string::npos) return true;
  return false;
}

std::vector<bool> pareto_front(const std::vector<glm::dvec2>& p, bool higher_is_better) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (std::isfinite(p[i].x) && std::isfinite(p[i].y)) idx.push_back(i);
  const double sign = higher_is_better ? 1.0 : -1.0;
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) {
    return p[a].x != p[b].x ? p[a].x < p[b].x : sign * p[a].y > sign * p[b].y;
  });
  std::vector<bool> front(p.size(), false);
  double best = -std::numeric_limits<double>::infinity();
  for (std::size_t i : idx)
    if (sign * p[i].y > best) {
      front[i] = true;
      best = sign * p[i].y;
    }
  return front;
}

namespace {

std::string fixed(double v, int decimals) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

// Times to three significant digits (a discrete GPU's frames take a few ms), factors to two.
std::string ms_text(double v) { return core::fixed_significant(v); }
std::string factor_text(double v) { return core::fixed_significant(v, 2); }

// A metric's value as table text: dB with 2 decimals, milliseconds to three significant
// digits, samples whole, the rest with 4 decimals. Repeated runs (report.repeat): their mean ±
// standard deviation, where it is not 0.
std::string md_value(const Row& r, const std::string& m) {
  if (!r.metrics.count(m)) return "–";
  const double v = r.metrics.at(m);
  // The spread takes the value's decimals.
  const int decimals = m.find("psnr") != std::string::npos      ? 2
                       : m.find("_ms") != std::string::npos     ? core::significant_decimals(v)
                       : m.find("samples") != std::string::npos ? 0
                                                                : 4;
  const auto sd = r.metrics.find(m + ".sd");
  const bool spread = sd != r.metrics.end() && sd->second > 1e-9 * std::max(1.0, std::abs(v));  // not rounding alone
  return fixed(v, decimals) + (spread ? " ± " + fixed(sd->second, decimals) : "");
}

// report.repeat: the done render jobs that differ only in the repeat setting (seeds) become one
// row without it: each metric's mean over them (where every run has it), "<metric>.sd" its
// sample standard deviation, "repeats" their count, each band's mean; `members` their ids.
// Every other row stays as it is.
std::vector<Row> merge_repeats(const std::vector<Row>& rows, const std::string& key) {
  std::vector<Row> out;
  std::vector<std::vector<const Row*>> runs;
  std::map<std::string, std::size_t> at;  // settings without the key -> index in out
  for (const Row& r : rows) {
    if (r.status != "done" || job_command(r.settings) != "render") {
      out.push_back(r);
      runs.emplace_back();
      continue;
    }
    json settings = r.settings;
    settings.erase(key);
    const auto [it, fresh] = at.emplace(settings.dump(), out.size());
    if (fresh) {
      out.push_back(r);
      out.back().settings = settings;
      runs.emplace_back();
    }
    runs[it->second].push_back(&r);
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    const std::vector<const Row*>& g = runs[i];
    for (const Row* r : g) out[i].members.push_back(r->id);
    if (g.size() < 2) continue;
    Row& m = out[i];
    const double n = double(g.size());
    m.metrics.clear();
    for (const auto& [name, first] : g[0]->metrics) {
      std::vector<double> v;
      for (const Row* r : g)
        if (const auto x = r->metrics.find(name); x != r->metrics.end()) v.push_back(x->second);
      if (v.size() != g.size()) continue;
      const double mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
      double sq = 0;
      for (double x : v) sq += (x - mean) * (x - mean);
      m.metrics[name] = mean;
      m.metrics[name + ".sd"] = std::sqrt(sq / (n - 1));
    }
    m.metrics["repeats"] = n;
    for (auto& [series, bands] : m.bands)
      for (std::size_t b = 0; b < bands.size(); ++b) {
        double sum = 0;
        int k = 0;
        for (const Row* r : g)
          if (const auto s = r->bands.find(series); s != r->bands.end() && s->second.size() == bands.size())
            sum += s->second[b].value, ++k;
        bands[b].value = sum / k;  // the runs that have the band (g[0] has it)
      }
  }
  return out;
}

struct MarkdownInput {
  const Plan& plan;
  const std::vector<Row>& rows;
  const Config& cfg;
  const std::map<std::string, std::map<std::string, bool>>& on_front;
  const std::vector<Section>& sections;                             // of the render jobs, in plan order
  const std::map<std::string, std::vector<std::string>>& images;  // per section, relative to the page
  const std::string& command;
};

// The exact command of a job, as the plan holds it ("fovea" is the program that ran it).
std::string job_argv_text(const Plan& plan, const std::string& id) {
  for (const Job& j : plan.jobs)
    if (j.id == id) {
      std::string s;
      for (const auto& a : j.argv) s += (s.empty() ? "" : " ") + a;
      return s;
    }
  return "";
}

// The options every job of one group ran with and no job of another group did (the Cartesian
// raster's filter, say), as `--key value` text; "" if none. A row names only its group and
// budget, so without these the page would not say how the group's jobs ran.
std::string group_options(const std::vector<const Row*>& done, const Config& cfg, const std::string& g) {
  std::map<std::string, json> shared;
  bool first = true;
  for (const Row* r : done) {
    if (group_text(*r, cfg.group) != g) continue;
    std::map<std::string, json> mine;
    for (auto it = r->settings.begin(); it != r->settings.end(); ++it)
      if (it.key() != cfg.group && it.key() != cfg.budget && it.key() != cfg.repeat) mine[it.key()] = *it;
    if (first) shared = mine, first = false;
    std::erase_if(shared, [&](const auto& kv) { return !mine.count(kv.first) || mine.at(kv.first) != kv.second; });
  }
  for (const Row* r : done)
    if (group_text(*r, cfg.group) != g)
      std::erase_if(shared, [&](const auto& kv) {
        return r->settings.contains(kv.first) && r->settings[kv.first] == kv.second;
      });
  std::string out;
  for (const auto& [k, v] : shared)
    out += (out.empty() ? "`--" : ", `--") + k + (v.is_boolean() ? "" : " " + setting_text(v)) + "`";
  return out;
}

void markdown_section(std::ostringstream& md, const MarkdownInput& in, const std::vector<const Row*>& done,
                      const std::string& h, const std::vector<std::string>& images);
void markdown_latency(std::ostringstream& md, const MarkdownInput& in, const std::vector<std::string>& images);
void markdown_speedup(std::ostringstream& md, const MarkdownInput& in, const std::vector<const Row*>& done,
                      const SpeedUp& su, bool first);

// The page: settings, every job, equal samples, equal time, per band, the plots, and what
// the Pareto front means for a 90 Hz frame.
// The blocks of an existing page that other tools write (a line `<!-- kept: NAME -->` to a
// line `<!-- /kept: NAME -->`, e.g. bench/handover.py's measurement), in their order: a
// regenerated page keeps them at its end.
std::string kept_blocks(const std::string& page) {
  std::string out;
  std::size_t at = 0;
  while ((at = page.find("<!-- kept: ", at)) != std::string::npos) {
    const std::size_t name_end = page.find(" -->", at);
    if (name_end == std::string::npos) break;
    const std::string close = "<!-- /kept: " + page.substr(at + 11, name_end - at - 11) + " -->";
    const std::size_t end = page.find(close, name_end);
    if (end == std::string::npos) break;
    out += "\n" + page.substr(at, end + close.size() - at) + "\n";
    at = end + close.size();
  }
  return out;
}

std::string markdown_page(const MarkdownInput& in) {
  const Config& cfg = in.cfg;
  std::vector<const Row*> done;
  for (const Row& r : in.rows)
    if (r.status == "done") done.push_back(&r);
  std::ostringstream md;
  md << "# Results: the sweep `" << in.plan.header.value("source", "") << "`\n\n"
     << "<!-- Generated by `fovea sweep report --markdown`; edit the sweep file or the generator, not this page. -->\n\n"
     << "Regenerate every number and picture on this page with one command (it plans and runs the sweep, "
        "resumably, then writes this page; docs/sweep.md gives its run time):\n\n    "
     << in.command << "\n\n";
  std::set<std::string> devices;
  std::size_t jobs_done = 0;
  for (const Row* r : done) devices.insert(r->device), jobs_done += std::max<std::size_t>(1, r->members.size());
  md << "Jobs: " << jobs_done << " done of " << in.plan.jobs.size() << ". Device: ";
  for (const auto& d : devices) md << (d == *devices.begin() ? "" : "; ") << d;
  md << ". Times are GPU timestamp medians per stereo frame (`" << cfg.time
     << "`), both eyes; quality is of the last frame against the shared converged reference (docs/metrics.md): "
        "FLIP is lower-is-better, PSNR (tone-mapped) higher-is-better; `fovea_*` over e ≤ 5.79°, `foveated_*` "
        "weighted by acuity. Means of both eyes.";
  if (!cfg.repeat.empty())
    md << " Jobs that differ only in `" << cfg.repeat << "` are one row: the mean of those runs ± their standard "
       << "deviation (the command shown is the first run's).";
  md << "\n\n";
  const bool sectioned = in.sections.size() > 1;
  if (sectioned) {
    std::string keys;
    for (const auto& k : cfg.section_keys) keys += (keys.empty() ? "" : " and ") + k;
    md << "One section per " << keys << ":";
    for (std::size_t i = 0; i < in.sections.size(); ++i) {
      std::string text = in.sections[i].id;
      std::replace(text.begin(), text.end(), '/', ' ');
      md << " [" << text << "](#" << anchor_of(in.sections[i].title) << ")" << (i + 1 == in.sections.size() ? "" : ",");
    }
    md << (in.images.count(kLatencySection) ? "; then [latency against quality](#latency-against-quality)" : "") << ".\n\n";
  }
  for (const SpeedUp& su : cfg.speedups) markdown_speedup(md, in, done, su, &su == &cfg.speedups.front());
  for (const auto& section : in.sections) {
    std::vector<const Row*> rows;
    for (const Row* r : done)
      if (job_command(r->settings) == "render" && section_of(*r, cfg) == section.id) rows.push_back(r);
    if (sectioned) md << "## " << section.title << "\n\n";
    const auto images = in.images.find(section.id);
    markdown_section(md, in, rows, sectioned ? "### " : "## ",
                     images != in.images.end() ? images->second : std::vector<std::string>{});
  }
  if (const auto l = in.images.find(kLatencySection); l != in.images.end()) markdown_latency(md, in, l->second);
  return md.str();
}

// One section's tables: every job at equal samples, equal time, per band, the plots, and
// what the Pareto front means for a 90 Hz frame.
void markdown_section(std::ostringstream& md, const MarkdownInput& in, const std::vector<const Row*>& done,
                      const std::string& h, const std::vector<std::string>& images) {
  const Config& cfg = in.cfg;
  auto setting = [](const Row& r, const std::string& k) {
    return r.settings.contains(k) ? setting_text(r.settings[k]) : std::string("–");
  };
  auto lower = [&](const std::string& q) { return cfg.lower_better(q); };
  const std::string q0 = cfg.quality.empty() ? "" : cfg.quality[0];
  if (!done.empty())
    md << "Each job is the command below with its row's settings (`shared/<id>`: the shared reference, "
          "`jobs/<id>`: its output, both in the sweep's results directory):\n\n    "
       << job_argv_text(in.plan, done.front()->id) << "\n\n";
  std::vector<std::string> groups;
  for (const Row* r : done)
    if (std::find(groups.begin(), groups.end(), setting(*r, cfg.group)) == groups.end())
      groups.push_back(setting(*r, cfg.group));
  for (const std::string& g : groups)
    if (const std::string options = group_options(done, cfg, g); !options.empty())
      md << "The " << g << " jobs also run with " << options << ".\n\n";

  // Every job, grouped by budget (equal samples), Pareto membership of the first quality.
  std::vector<const Row*> sorted = done;
  std::stable_sort(sorted.begin(), sorted.end(), [&](const Row* a, const Row* b) {
    const double ba = a->settings.contains(cfg.budget) && a->settings[cfg.budget].is_number() ? a->settings[cfg.budget].get<double>() : 2;
    const double bb = b->settings.contains(cfg.budget) && b->settings[cfg.budget].is_number() ? b->settings[cfg.budget].get<double>() : 2;
    return ba != bb ? ba < bb : setting(*a, cfg.group) < setting(*b, cfg.group);
  });
  md << h << "Equal samples: every job by " << cfg.budget << "\n\n| " << cfg.group << " | " << cfg.budget
     << " | samples/eye | " << cfg.time;
  for (const auto& q : cfg.quality) md << " | " << q;
  md << " | on the " << q0 << " front |\n|---|---|---|---";
  for (std::size_t i = 0; i <= cfg.quality.size(); ++i) md << "|---";
  md << "|\n";
  for (const Row* r : sorted) {
    md << "| " << setting(*r, cfg.group) << " | " << setting(*r, cfg.budget) << " | " << md_value(*r, "samples_traced_per_eye")
       << " | " << md_value(*r, cfg.time);
    for (const auto& q : cfg.quality) md << " | " << md_value(*r, q);
    const auto f = in.on_front.find(q0);
    md << " | " << (f != in.on_front.end() && f->second.count(r->id) && f->second.at(r->id) ? "yes" : "") << " |\n";
  }

  // Which to pick: the best first quality, and the fastest job within 5% of it; then the
  // first group against each other group at equal budget.
  if (!q0.empty() && !groups.empty()) {
    const auto better = [&](double a, double b) { return lower(q0) ? a < b : a > b; };
    const Row* best = nullptr;
    for (const Row* r : done)
      if (r->metrics.count(q0) && (!best || better(r->metrics.at(q0), best->metrics.at(q0)))) best = r;
    if (best) {
      const double b = best->metrics.at(q0), slack = 0.05 * std::abs(b);
      const Row* pick = nullptr;
      for (const Row* r : done)
        if (r->metrics.count(q0) && r->metrics.count(cfg.time) && !better(b + (lower(q0) ? slack : -slack), r->metrics.at(q0)) &&
            (!pick || r->metrics.at(cfg.time) < pick->metrics.at(cfg.time)))
          pick = r;
      const auto name = [&](const Row& r) {
        return setting(r, cfg.group) + (r.settings.contains(cfg.budget) ? " at " + cfg.budget + " " + setting(r, cfg.budget) : "");
      };
      md << "\n" << h << "Which to pick\n\n- Best " << q0 << ": " << name(*best) << " (" << md_value(*best, q0) << ", "
         << md_value(*best, cfg.time) << " ms).\n";
      if (pick)
        md << "- The fastest within 5% of it: " << name(*pick) << " (" << md_value(*pick, q0) << ", "
           << md_value(*pick, cfg.time) << " ms).\n";
      const std::string anchor = groups[0];
      for (const std::string& g : groups) {
        if (g == anchor) continue;
        int both = 0, wins = 0;
        for (const Row* a : done)
          for (const Row* o : done)
            if (setting(*a, cfg.group) == anchor && setting(*o, cfg.group) == g && a->settings.contains(cfg.budget) &&
                o->settings.contains(cfg.budget) && a->settings[cfg.budget] == o->settings[cfg.budget] &&
                a->metrics.count(q0) && o->metrics.count(q0)) {
              ++both;
              wins += better(a->metrics.at(q0), o->metrics.at(q0));
            }
        if (both)
          md << "- " << anchor << " against " << g << " in " << q0 << " at equal " << cfg.budget << ": better at " << wins
             << " of " << both << ".\n";
      }
    }
  }

  // Equal time: each group's best quality within the time of each job of the first group.
  if (!q0.empty() && !groups.empty()) {
    const std::string anchor = groups[0];
    std::vector<double> limits;
    for (const Row* r : done)
      if (setting(*r, cfg.group) == anchor && r->metrics.count(cfg.time)) limits.push_back(r->metrics.at(cfg.time));
    std::sort(limits.begin(), limits.end());
    md << "\n" << h << "Equal time: best " << q0 << " within each " << anchor << " job's time\n\n"
       << "Each cell: the best " << q0 << " of that " << cfg.group << "'s jobs whose " << cfg.time
       << " is at most the limit (– if none is that fast).\n\n| " << cfg.time << " ≤";
    for (const auto& g : groups) md << " | " << g;
    md << " |\n|---";
    for (std::size_t i = 0; i < groups.size(); ++i) md << "|---";
    md << "|\n";
    for (double t : limits) {
      md << "| " << ms_text(t);
      for (const auto& g : groups) {
        const Row* best = nullptr;
        for (const Row* r : done)
          if (setting(*r, cfg.group) == g && r->metrics.count(cfg.time) && r->metrics.count(q0) &&
              r->metrics.at(cfg.time) <= t &&
              (!best || (lower(q0) ? r->metrics.at(q0) < best->metrics.at(q0) : r->metrics.at(q0) > best->metrics.at(q0))))
            best = r;
        md << " | " << (best ? md_value(*best, q0) + " (" + cfg.budget + " " + setting(*best, cfg.budget) + ")" : "–");
      }
      md << " |\n";
    }
  }

  // Per band: the first band series with "psnr" (tone-mapped PSNR per 2° band), every job.
  std::string band_series;
  for (const Row* r : done)
    for (const auto& [k, v] : r->bands)
      if (band_series.empty() && k.find("psnr") != std::string::npos) band_series = k;
  if (!band_series.empty()) {
    std::vector<BandValue> edges;
    for (const Row* r : done)
      if (r->bands.count(band_series) && r->bands.at(band_series).size() > edges.size()) edges = r->bands.at(band_series);
    const std::size_t shown = std::min<std::size_t>(edges.size(), 10);
    md << "\n" << h << "Per band: `" << band_series << "` (dB) per eccentricity band\n\n| " << cfg.group << " | " << cfg.budget;
    for (std::size_t b = 0; b < shown; ++b) md << " | " << cell(edges[b].e_min) << "–" << cell(edges[b].e_max) << "°";
    md << " |\n|---|---";
    for (std::size_t b = 0; b < shown; ++b) md << "|---";
    md << "|\n";
    for (const Row* r : sorted) {
      md << "| " << setting(*r, cfg.group) << " | " << setting(*r, cfg.budget);
      const auto& bv = r->bands.count(band_series) ? r->bands.at(band_series) : std::vector<BandValue>{};
      for (std::size_t b = 0; b < shown; ++b) {
        std::string v = "–";
        for (const BandValue& x : bv)
          if (std::abs(x.e_min - edges[b].e_min) < 1e-9) v = fixed(x.value, 2);
        md << " | " << v;
      }
      md << " |\n";
    }
  }

  md << "\n" << h << "Plots\n\n";
  for (const auto& f : images) md << "![" << f << "](" << f << ")\n\n";

  // 90 Hz: the front of the first quality, each job's cost relative to the full raster and
  // the speed-up a device needs for 11.1 ms at a display with more pixels.
  if (!q0.empty()) {
    const Row* full = nullptr;
    for (const Row* r : done)
      if (setting(*r, cfg.group) == "cartesian" && r->metrics.count(cfg.time)) full = r;
    std::vector<const Row*> front;
    const auto f = in.on_front.find(q0);
    for (const Row* r : done)
      if (f != in.on_front.end() && f->second.count(r->id) && f->second.at(r->id) && r->metrics.count(cfg.time)) front.push_back(r);
    std::sort(front.begin(), front.end(), [&](const Row* a, const Row* b) { return a->metrics.at(cfg.time) < b->metrics.at(cfg.time); });
    md << h << "Towards 90 Hz (11.1 ms per frame)\n\nThe " << q0 << " Pareto fronts (every " << cfg.group
       << "), cheapest first. *Cost* is the job's " << cfg.time << " over the full-raster cartesian job's; "
       << "*speed-up for 11.1 ms* is how much faster than this machine a device must run it for a 90 Hz frame at this "
          "display, and ×16 that for `fove0` (1280×1440 per eye, 16× the pixels of `small`), assuming the cost "
          "scales with the pixels (every stage here is per cell or per pixel).\n\n"
       << "| " << cfg.group << " | " << cfg.budget << " | " << cfg.time << " | " << q0
       << " | cost vs cartesian | speed-up for 11.1 ms | same for fove0 |\n|---|---|---|---|---|---|---|\n";
    for (const Row* r : front) {
      const double t = r->metrics.at(cfg.time);
      md << "| " << setting(*r, cfg.group) << " | " << setting(*r, cfg.budget) << " | " << ms_text(t) << " | "
         << md_value(*r, q0) << " | " << (full ? fixed(t / full->metrics.at(cfg.time), 2) : "–") << " | "
         << factor_text(t / 11.1) << "× | " << factor_text(16 * t / 11.1) << "× |\n";
    }
    if (full)
      md << "| cartesian (baseline) | – | " << ms_text(full->metrics.at(cfg.time)) << " | " << md_value(*full, q0)
         << " | 1.00 | " << factor_text(full->metrics.at(cfg.time) / 11.1) << "× | "
         << factor_text(16 * full->metrics.at(cfg.time) / 11.1) << "× |\n";
    // The pick: the cheapest front job within 10% of the best score any job reached.
    const Row* best = nullptr;
    for (const Row* r : done)
      if (r->metrics.count(q0) && (!best || (lower(q0) ? r->metrics.at(q0) < best->metrics.at(q0)
                                                       : r->metrics.at(q0) > best->metrics.at(q0))))
        best = r;
    for (const Row* r : front) {
      if (!best) break;
      const double b = best->metrics.at(q0), v = r->metrics.at(q0);
      if (lower(q0) ? v > b + 0.1 * std::abs(b) : v < b - 0.1 * std::abs(b)) continue;
      const double t = r->metrics.at(cfg.time);
      md << "\n**Pick** (rule: the cheapest front job whose " << q0 << " is within 10% of the best job's "
         << md_value(*best, q0) << "): " << setting(*r, cfg.group) << " at " << cfg.budget << " "
         << setting(*r, cfg.budget) << ", " << md_value(*r, q0) << " in " << ms_text(t) << " ms"
         << (full ? ", " + fixed(t / full->metrics.at(cfg.time), 2) + "× the cartesian job's time" : std::string())
         << ". For 90 Hz on `fove0` a device must run it ≈" << factor_text(16 * t / 11.1)
         << "× faster than this machine did; the ranking, not the absolute time, is what carries over.\n";
      break;
    }
  }
}

// report.speedup: per section, the `over` job against the cheapest `of` job whose qualities are
// each at least as good (within the tolerance), or against the `of` job at each budget of `at`:
// whole-frame times on the GPU and the CPU, traced samples, and how much of the samples'
// ratio the time's ratio keeps.
void markdown_speedup(std::ostringstream& md, const MarkdownInput& in, const std::vector<const Row*>& done,
                      const SpeedUp& su, bool first) {
  const Config& cfg = in.cfg;
  std::vector<std::string> qs = su.quality;
  if (qs.empty() && !cfg.quality.empty()) qs.push_back(cfg.quality[0]);
  const std::string q = qs.empty() ? "" : qs[0];  // the one in the table's columns
  const bool at_budgets = !su.at.empty();
  if (q.empty() && !at_budgets) return;
  const bool lower = !q.empty() && cfg.lower_better(q);
  std::string qs_text;  // "a", "a and b", "a, b and c"
  for (std::size_t i = 0; i < qs.size(); ++i) qs_text += (i == 0 ? "" : i + 1 == qs.size() ? " and " : ", ") + qs[i];
  // As good in each quality: at most (lower-is-better) or at least 1 ± tolerance times the `over` job's.
  const auto as_good = [&](const Row& r, const Row& over) {
    for (const auto& m : qs) {
      const double v = r.metrics.at(m), ref = over.metrics.at(m), slack = su.tolerance * std::abs(ref);
      if (cfg.lower_better(m) ? v > ref + slack : v < ref - slack) return false;
    }
    return true;
  };
  const auto has_qualities = [&](const Row& r) {
    return std::all_of(qs.begin(), qs.end(), [&](const std::string& m) { return r.metrics.count(m) > 0; });
  };
  const std::string cpu = "cpu_ms.total", samples = "samples_traced_per_eye", trace = "gpu_ms.trace";
  const auto group = [&](const Row& r) { return group_text(r, cfg.group); };
  const auto ratio = [](const Row& a, const Row& b, const std::string& m) {
    return a.metrics.count(m) && b.metrics.count(m) && b.metrics.at(m) > 0 ? fixed(a.metrics.at(m) / b.metrics.at(m), 2)
                                                                           : std::string("–");
  };
  const std::string quality_name = q.empty() ? "quality" : q;
  if (at_budgets) {
    std::string list;
    for (double b : su.at) list += (list.empty() ? "" : ", ") + setting_text(json(b));
    md << "## " << su.of << " against " << su.over << " at " << cfg.budget << " " << list << "\n\n"
       << "Per section: the " << su.over << " job, and the " << su.of << " job at each " << cfg.budget << " listed.";
  } else {
    md << "## " << su.of << " against " << su.over << " at equal " << qs_text << "\n\n"
       << "Per section: the " << su.over << " job, and the cheapest " << su.of << " job (by `" << cfg.time
       << "`) whose " << qs_text << (qs.size() > 1 ? " are each" : " is") << " at least as good as its, within "
       << fixed(100 * su.tolerance, 0) << "% (\"as good\": ";
    const std::string t = fixed(su.tolerance, 2);
    if (qs.size() == 1)
      md << (lower ? "at most 1 + " : "at least 1 − ") << t << " times the " << su.over << " job's).";
    else
      md << "at most 1 + " << t << " times the " << su.over << " job's where lower is better, at least 1 − " << t
         << " times where higher is).";
  }
  for (const std::string& g : {su.over, su.of})
    if (const std::string options = group_options(done, cfg, g); !options.empty())
      md << " The " << g << " jobs run with " << options << ".";
  if (!first)
    md << " The columns are those of the first table.";
  else
    md << " *Speed-up*: the " << su.over << " job's whole-frame time over the " << su.of << " job's (GPU: `"
       << cfg.time << "`, CPU: `" << cpu << "`, both per stereo frame, every stage); *samples ratio*: traced samples "
       << "per eye, " << su.over << " over " << su.of << "; the last column is how much of the samples' ratio the GPU "
       << "speed-up keeps (1 = cost follows the samples); *trace per 1000 samples*: `" << trace << "` per 1000 traced "
       << "samples per eye, " << su.over << " / " << su.of << " and the second over the first (1 = a sample costs the "
       << "same to trace); *other quality*: the other quality metrics, " << su.over << " → " << su.of << ".";
  md << "\n\n| section | " << su.over << " samples/eye | " << su.over << " GPU / CPU ms | " << su.over << " "
     << quality_name << " | " << su.of << " " << cfg.budget << " | " << su.of << " samples/eye | " << su.of
     << " GPU / CPU ms | " << su.of << " " << quality_name << " | GPU speed-up | CPU speed-up | samples ratio | "
     << "speed-up / samples ratio | trace per 1000 samples | other quality |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  const auto budget_of = [&](const Row& r) {
    return r.settings.contains(cfg.budget) && r.settings[cfg.budget].is_number() ? r.settings[cfg.budget].get<double>()
                                                                                  : NAN;
  };
  for (const Section& section : in.sections) {
    const Row* over = nullptr;
    std::vector<const Row*> of;
    for (const Row* r : done) {
      if (job_command(r->settings) != "render" || section_of(*r, cfg) != section.id || !r->metrics.count(cfg.time) ||
          (!at_budgets && !has_qualities(*r)))
        continue;
      if (group(*r) == su.over && (!over || r->metrics.at(cfg.time) < over->metrics.at(cfg.time))) over = r;
      if (group(*r) == su.of) of.push_back(r);
    }
    if (!over || of.empty()) continue;
    const auto times = [&](const Row& r) { return md_value(r, cfg.time) + " / " + md_value(r, cpu); };
    const auto head = [&] {  // the section and its `over` job
      md << "| " << section.title << " | " << md_value(*over, samples) << " | " << times(*over) << " | "
         << (q.empty() ? "–" : md_value(*over, q)) << " | ";
    };
    const auto row = [&](const Row* pick) {
      head();
      const std::string speed_up = ratio(*over, *pick, cfg.time), samples_ratio = ratio(*over, *pick, samples);
      const double kept = pick->metrics.count(samples) && over->metrics.count(samples) && pick->metrics.at(samples) > 0
                              ? (over->metrics.at(cfg.time) / pick->metrics.at(cfg.time)) /
                                    (over->metrics.at(samples) / pick->metrics.at(samples))
                              : NAN;
      md << (pick->settings.contains(cfg.budget) ? setting_text(pick->settings[cfg.budget]) : "–") << " | "
         << md_value(*pick, samples) << " | " << times(*pick) << " | " << (q.empty() ? "–" : md_value(*pick, q))
         << " | **" << speed_up << "×** | " << ratio(*over, *pick, cpu) << "× | " << samples_ratio << " | "
         << (std::isfinite(kept) ? fixed(kept, 2) : "–") << " | ";
      // The trace's cost per traced sample (issue goal: the same for every distribution).
      const auto per_1000 = [&](const Row& r) {
        return r.metrics.count(trace) && r.metrics.count(samples) && r.metrics.at(samples) > 0
                   ? 1000 * r.metrics.at(trace) / r.metrics.at(samples)
                   : NAN;
      };
      const double a = per_1000(*over), b = per_1000(*pick);
      if (std::isfinite(a) && std::isfinite(b) && a > 0)
        md << ms_text(a) << " / " << ms_text(b) << " (" << fixed(b / a, 2) << ")";
      else
        md << "–";
      md << " |";
      std::string other;
      for (const auto& m : cfg.quality)
        if (m != q)
          other += (other.empty() ? " " : "; ") + m + " " + md_value(*over, m) + " → " + md_value(*pick, m);
      md << other << " |\n";
    };
    if (at_budgets) {
      for (double b : su.at) {
        const Row* pick = nullptr;
        for (const Row* r : of)
          if (std::abs(budget_of(*r) - b) <= 1e-9 * std::max(1.0, std::abs(b)) &&
              (!pick || r->metrics.at(cfg.time) < pick->metrics.at(cfg.time)))
            pick = r;
        if (pick) row(pick);
      }
      continue;
    }
    const Row* pick = nullptr;
    for (const Row* r : of)
      if (as_good(*r, *over) && (!pick || r->metrics.at(cfg.time) < pick->metrics.at(cfg.time))) pick = r;
    if (pick) {
      row(pick);
      continue;
    }
    const Row* best = of.front();
    for (const Row* r : of)
      if (lower ? r->metrics.at(q) < best->metrics.at(q) : r->metrics.at(q) > best->metrics.at(q)) best = r;
    head();
    md << "none as good" << (qs.size() > 1 ? " in each (best " + q + ": " : " (best: ") << md_value(*best, q) << " at "
       << cfg.budget << " "
       << (best->settings.contains(cfg.budget) ? setting_text(best->settings[cfg.budget]) : "–")
       << ") | – | – | – | – | – | – | – | – | – |\n";
  }
  md << "\n";
}

// Latency jobs: their settings, gaze-to-photon, foveal error and fovea quality, the plots.
void markdown_latency(std::ostringstream& md, const MarkdownInput& in, const std::vector<std::string>& images) {
  const Config& cfg = in.cfg;
  std::vector<Row> rows;
  for (const Row& r : in.rows)
    if (r.status == "done" && r.metrics.count(cfg.latency)) rows.push_back(r);
  std::vector<std::string> keys = varied_keys(rows);
  keys.erase(std::remove(keys.begin(), keys.end(), cfg.latency_group), keys.end());
  keys.insert(keys.begin(), cfg.latency_group);
  std::vector<std::string> metrics = {cfg.latency};
  if (cfg.latency != "foveal_error_deg.median") metrics.push_back("foveal_error_deg.median");
  for (const auto& q : cfg.latency_quality)
    if (std::find(metrics.begin(), metrics.end(), q) == metrics.end()) metrics.push_back(q);
  md << "\n## Latency against quality\n\n";
  if (!rows.empty())
    md << "Each job is the command below with its row's settings; quality is the fovea's at the job's own latency "
          "(docs/latency.md):\n\n    "
       << job_argv_text(in.plan, rows.front().id) << "\n\n";
  md << "|";
  for (const auto& k : keys) md << " " << k << " |";
  for (const auto& m : metrics) md << " " << m << " |";
  md << "\n|";
  for (std::size_t i = 0; i < keys.size() + metrics.size(); ++i) md << "---|";
  md << "\n";
  for (const Row& r : rows) {
    md << "|";
    for (const auto& k : keys) md << " " << (r.settings.contains(k) ? setting_text(r.settings[k]) : "–") << " |";
    for (const auto& m : metrics) {
      const int decimals = m.find("_ms") != std::string::npos ? 1 : m.find("psnr") != std::string::npos ? 2 : 4;
      md << " " << (r.metrics.count(m) ? fixed(r.metrics.at(m), decimals) : "–") << " |";
    }
    md << "\n";
  }
  md << "\n";
  for (const auto& f : images) md << "![" << f << "](" << f << ")\n\n";
}

}  // namespace

ReportSummary write_report(const Plan& plan, const ReportOptions& o) {
  const fs::path dir(o.dir), out(o.out);
  ReportSummary sum;
  std::vector<Row> rows;
  json failed = json::array(), missing = json::array();
  for (const Job& j : plan.jobs) {
    Row r{j.id, "missing", j.settings, {}, {}};
    // A render job's report.json; a latency job's summary.json.
    const bool latency = job_command(j.settings) == "latency";
    const fs::path rep = dir / j.out / (latency ? "summary.json" : "report.json");
    if (fs::exists(dir / j.out)) {
      std::ifstream in(rep);
      if (!in) throw core::InputError(rep.string() + ": finished job without " + rep.filename().string());
      json rj;
      try {
        rj = core::parse_json(in);
      } catch (const json::parse_error& e) {
        throw core::InputError(rep.string() + ": not valid JSON (" + e.what() + ")");
      }
      r.metrics = latency ? latency_metrics(rj) : flatten_metrics(rj);
      const json device = rj.contains("device")                             ? rj["device"]
                          : rj.contains("config") && rj["config"].is_object() ? rj["config"].value("device", json())
                                                                            : json();
      if (device.is_object()) r.device = device.value("name", "") + ", " + device.value("driver", "");
      r.bands = band_metrics(rj);
      std::ifstream tin(dir / j.out / "task.json");
      if (tin) {
        const json t = core::parse_json_or_discarded(tin);
        if (t.is_object() && t.contains("seconds") && t["seconds"].is_number()) r.metrics["wall_seconds"] = t["seconds"];
      }
      r.status = "done";
      ++sum.done;
    } else if (fs::exists(dir / "failed" / (j.id + ".json"))) {
      std::ifstream in(dir / "failed" / (j.id + ".json"));
      const json f = core::parse_json_or_discarded(in);
      failed.push_back(f.is_discarded() ? json{{"id", j.id}} : f);
      r.status = "failed";
      ++sum.failed;
    } else {
      missing.push_back(j.id);
      ++sum.missing;
    }
    rows.push_back(std::move(r));
  }
  const Config cfg = read_config(plan.header.value("report", json::object()), rows);
  // The page and the plots show repeated runs as one row (report.repeat); the CSV and JSON list every job.
  const std::vector<Row> shown = cfg.repeat.empty() ? rows : merge_repeats(rows, cfg.repeat);
  const std::vector<std::string> varied = varied_keys(shown);
  auto group_of = [&](const Row& r) { return r.settings.contains(cfg.group) ? setting_text(r.settings[cfg.group]) : std::string("all"); };
  auto label_of = [&](const Row& r) {
    std::string s;
    for (const auto& k : varied)
      if (k != cfg.group && std::count(cfg.section_keys.begin(), cfg.section_keys.end(), k) == 0 && r.settings.contains(k))
        s += (s.empty() ? "" : " ") + k + "=" + setting_text(r.settings[k]);
    return s;
  };
  // Render jobs are compared within a section (a scene): their own fronts, plots and tables.
  std::vector<Section> sections;
  for (const auto& r : shown)
    if (r.status == "done" && job_command(r.settings) == "render" &&
        std::none_of(sections.begin(), sections.end(), [&](const Section& s) { return s.id == section_of(r, cfg); }))
      sections.push_back({section_of(r, cfg), section_title(r, cfg)});
  const bool sectioned = sections.size() > 1;
  fs::create_directories(out);
  std::map<std::string, std::vector<std::string>> section_files;  // section -> PNGs; latency plots under kLatencySection
  std::vector<Chart> charts;  // drawn together at the end (figures.json)
  auto save = [&](Chart c, const std::string& stem, const std::string& section) {
    c.file = stem;
    charts.push_back(std::move(c));
    section_files[section].push_back(stem + ".png");
  };

  std::map<std::string, std::map<std::string, bool>> on_front;  // quality -> id -> flag
  json fronts = json::object();
  for (const auto& [section, title] : sections) {
    std::vector<const Row*> members_of_section;
    for (const auto& r : shown)
      if (r.status == "done" && job_command(r.settings) == "render" && section_of(r, cfg) == section) members_of_section.push_back(&r);
    std::vector<std::string> groups;
    for (const Row* r : members_of_section)
      if (std::find(groups.begin(), groups.end(), group_of(*r)) == groups.end()) groups.push_back(group_of(*r));
    const std::string suffix = sectioned ? "_" + file_stem(section) : "";
    const std::string where = sectioned ? ", " + title : "";
    // Pareto fronts of quality against time, per group.
    for (const auto& q : cfg.quality) {
      Chart ch;
      ch.title = human_name(q) + " against time per frame" + where;
      ch.note = "ringed: Pareto front per " + cfg.group + " (" + (cfg.lower_better(q) ? "lower" : "higher") + " " +
                human_name(q) + " is better, less time is better); labels: " + cfg.budget;
      ch.x_label = axis_label(cfg.time) + " per stereo frame";
      ch.y_label = axis_label(q);
      for (std::size_t g = 0; g < groups.size(); ++g) {
        std::vector<const Row*> members;
        std::vector<glm::dvec2> pts;
        std::vector<std::string> budgets_of;
        for (const Row* r : members_of_section)
          if (group_of(*r) == groups[g] && r->metrics.count(cfg.time) && r->metrics.count(q)) {
            members.push_back(r);
            pts.push_back({r->metrics.at(cfg.time), r->metrics.at(q)});
            budgets_of.push_back(r->settings.contains(cfg.budget) ? setting_text(r->settings[cfg.budget]) : "");
          }
        if (pts.empty()) continue;
        const std::vector<bool> f = pareto_front(pts, !cfg.lower_better(q));
        Series s{groups[g], g, pts, false, true};
        s.emphasised = f;
        s.point_labels = budgets_of;
        Series line{"", g, {}, true, false};
        json ids = json::array();
        std::vector<std::pair<glm::dvec2, std::string>> fp;
        for (std::size_t i = 0; i < pts.size(); ++i) {
          on_front[q][members[i]->id] = f[i];
          if (f[i]) fp.push_back({pts[i], members[i]->id});
        }
        std::sort(fp.begin(), fp.end(), [](const auto& a, const auto& b) { return a.first.x < b.first.x; });
        for (const auto& [p, id] : fp) line.points.push_back(p), ids.push_back(id);
        fronts[q][sectioned ? section + "/" + groups[g] : groups[g]] = ids;
        ch.series.push_back(line);
        ch.series.push_back(s);
      }
      if (!ch.series.empty()) save(ch, "quality_vs_time_" + file_stem(q) + suffix, section);

      // Quality against budget: the best job at each budget, per group.
      std::set<std::string> budgets;
      for (const Row* r : members_of_section)
        if (r->settings.contains(cfg.budget)) budgets.insert(r->settings[cfg.budget].dump());
      if (budgets.size() > 1) {
        Chart cb;
        cb.title = human_name(q) + " against " + cfg.budget + where;
        cb.note = "best job at each " + cfg.budget + " over the other settings, per " + cfg.group;
        cb.x_label = cfg.budget == "budget" ? "budget (grid samples / display pixels)" : cfg.budget;
        cb.y_label = axis_label(q);
        for (std::size_t g = 0; g < groups.size(); ++g) {
          std::map<double, double> best;
          for (const Row* r : members_of_section)
            if (group_of(*r) == groups[g] && r->metrics.count(q) && r->settings.contains(cfg.budget) &&
                r->settings[cfg.budget].is_number()) {
              const double b = r->settings[cfg.budget].get<double>(), v = r->metrics.at(q);
              auto it = best.find(b);
              if (it == best.end() || (cfg.lower_better(q) ? v < it->second : v > it->second)) best[b] = v;
            }
          Series s{groups[g], g, {}, true, true};
          for (const auto& [b, v] : best) s.points.push_back({b, v});
          if (!s.points.empty()) cb.series.push_back(s);
        }
        if (!cb.series.empty()) save(cb, "quality_vs_budget_" + file_stem(q) + suffix, section);
      }
    }

    // Per-band curves of the jobs on the first quality metric's fronts (at most 8 lines).
    std::set<std::string> band_names;
    for (const Row* r : members_of_section)
      for (const auto& [k, v] : r->bands)
        if (cfg.bands.empty() || std::find(cfg.bands.begin(), cfg.bands.end(), k) != cfg.bands.end()) band_names.insert(k);
    for (const auto& bname : band_names) {
      Chart cb;
      cb.title = human_name(bname) + " per eccentricity band" + where;
      cb.note = cfg.quality.empty() ? "" : "jobs on the " + human_name(cfg.quality[0]) + " Pareto fronts";
      cb.x_label = "eccentricity, band centre (deg)";
      cb.y_label = axis_label(bname);
      std::size_t n = 0;
      for (const Row* r : members_of_section) {
        if (!r->bands.count(bname) || n >= 8) continue;
        if (!cfg.quality.empty() && !on_front[cfg.quality[0]][r->id]) continue;
        Series s{group_of(*r) + " " + label_of(*r), n++, {}, true, true};
        for (const BandValue& b : r->bands.at(bname)) s.points.push_back({0.5 * (b.e_min + b.e_max), b.value});
        cb.series.push_back(s);
      }
      if (!cb.series.empty()) save(cb, "bands_" + file_stem(bname) + suffix, section);
    }
  }

  // Latency against quality: every job that reports the latency metric, one series per
  // value of the latency group (e.g. each predict mode), joined by increasing latency.
  if (!cfg.latency.empty()) {
    std::vector<std::string> lgroups;
    auto lgroup_of = [&](const Row& r) {
      return r.settings.contains(cfg.latency_group) ? setting_text(r.settings[cfg.latency_group]) : std::string("all");
    };
    for (const auto& r : shown)
      if (r.status == "done" && r.metrics.count(cfg.latency) &&
          std::find(lgroups.begin(), lgroups.end(), lgroup_of(r)) == lgroups.end())
        lgroups.push_back(lgroup_of(r));
    for (const auto& q : cfg.latency_quality) {
      Chart cl;
      cl.title = human_name(q) + " against " + human_name(cfg.latency);
      cl.note = "one point per job; legend: " + cfg.latency_group + " (" + (cfg.lower_better(q) ? "lower" : "higher") +
                " is better)";
      cl.x_label = axis_label(cfg.latency);
      cl.y_label = axis_label(q);
      for (std::size_t g = 0; g < lgroups.size(); ++g) {
        Series s{cfg.latency_group + " " + lgroups[g], g, {}, true, true};
        for (const auto& r : shown)
          if (r.status == "done" && lgroup_of(r) == lgroups[g] && r.metrics.count(q) && r.metrics.count(cfg.latency))
            s.points.push_back({r.metrics.at(cfg.latency), r.metrics.at(q)});
        std::sort(s.points.begin(), s.points.end(), [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x; });
        if (!s.points.empty()) cl.series.push_back(s);
      }
      if (!cl.series.empty()) save(cl, "latency_vs_" + file_stem(q), kLatencySection);
    }
  }
  sum.files = write_charts(out.string(), "figures.json", charts);
  for (const Row& r : shown)  // a row of repeated runs: its front membership is each run's
    for (const std::string& id : r.members)
      for (auto& [q, flags] : on_front)
        if (flags.count(r.id)) flags[id] = flags[r.id];
  // results.csv: one row per job; settings, metrics and bands as columns.
  std::set<std::string> setting_cols, metric_cols, band_cols;
  for (const auto& r : rows) {
    for (auto it = r.settings.begin(); it != r.settings.end(); ++it) setting_cols.insert(it.key());
    for (const auto& [k, v] : r.metrics) metric_cols.insert(k);
  }
  auto band_col = [](const std::string& name, const BandValue& b) { return name + "[" + cell(b.e_min) + "-" + cell(b.e_max) + "]"; };
  std::vector<std::string> band_order;
  for (const auto& r : rows)
    for (const auto& [k, v] : r.bands)
      for (const auto& b : v)
        if (band_cols.insert(band_col(k, b)).second) band_order.push_back(band_col(k, b));
  std::string csv = "id,status";
  for (const auto& k : setting_cols) csv += ",--" + csv_escape(k);  // the render option
  for (const auto& k : metric_cols) csv += "," + csv_escape(k);
  for (const auto& k : band_order) csv += "," + csv_escape(k);
  for (const auto& q : cfg.quality) csv += ",pareto:" + csv_escape(q);
  csv += "\n";
  json jobs = json::array();
  for (const auto& r : rows) {
    csv += r.id + "," + r.status;
    for (const auto& k : setting_cols) csv += "," + (r.settings.contains(k) ? csv_escape(setting_text(r.settings[k])) : "");
    for (const auto& k : metric_cols) csv += "," + (r.metrics.count(k) ? cell(r.metrics.at(k)) : "");
    std::map<std::string, double> bands;
    json jb = json::object();
    for (const auto& [k, v] : r.bands)
      for (const auto& b : v) {
        bands[band_col(k, b)] = b.value;
        jb[k].push_back({{"e_min", b.e_min}, {"e_max", b.e_max}, {"value", b.value}});
      }
    for (const auto& k : band_order) csv += "," + (bands.count(k) ? cell(bands[k]) : "");
    json jp = json::object();
    for (const auto& q : cfg.quality) {
      const bool f = on_front[q].count(r.id) && on_front[q][r.id];
      csv += f ? ",1" : ",0";
      jp[q] = f;
    }
    csv += "\n";
    jobs.push_back({{"id", r.id}, {"status", r.status}, {"settings", r.settings}, {"metrics", r.metrics}, {"bands", jb}, {"pareto", jp}});
  }
  core::write_file_atomic((out / "results.csv").string(), csv);
  sum.files.insert(sum.files.begin(), "results.csv");
  json j = {{"source", plan.header.value("source", "")},
            {"quality", cfg.quality},
            {"time", cfg.time},
            {"group", cfg.group},
            {"jobs", jobs},
            {"pareto", fronts},
            {"failed", failed},
            {"missing", missing},
            {"counts", {{"done", sum.done}, {"failed", sum.failed}, {"missing", sum.missing}}}};
  sum.files.insert(sum.files.begin() + 1, "results.json");
  j["files"] = sum.files;
  core::write_file_atomic((out / "results.json").string(), j.dump(2) + "\n");
  if (!o.markdown.empty()) {
    const fs::path page(o.markdown);
    std::map<std::string, std::vector<std::string>> images;
    for (const auto& [section, files] : section_files)
      for (const auto& f : files)
        images[section].push_back(
            fs::relative(out / f, page.parent_path().empty() ? fs::path(".") : page.parent_path()).string());
    if (!page.parent_path().empty()) fs::create_directories(page.parent_path());
    std::error_code ec;
    const std::string kept =
        fs::is_regular_file(page, ec) ? kept_blocks(core::read_file_bounded(page.string(), 64 << 20)) : std::string();
    core::write_file_atomic(page.string(),
                            markdown_page({plan, shown, cfg, on_front, sections, images, o.command}) + kept);
  }
  return sum;
}

}  // namespace fovea::sweep
