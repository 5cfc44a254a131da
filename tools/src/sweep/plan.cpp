#include "sweep/plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "fovea/core/error.hpp"
#include "fovea/pipeline/frame_config.hpp"
#include "fovea/core/json.hpp"

namespace fovea::sweep {
namespace {

using nlohmann::json;
using core::InputError;

constexpr std::size_t kMaxJobs = 100000;
constexpr std::size_t kMaxRangeValues = 10000;

// Sweep-file keys that are not render options; the plural ones map onto render options.
const std::map<std::string, std::string> kAliases = {{"scenes", "scene"}, {"displays", "display"}};
// Options the runner sets itself.
const std::set<std::string> kReserved = {"out", "quiet", "help"};

std::string where(const std::string& source, const std::string& key) { return source + ": key \"" + key + "\""; }

// Rounds away the binary noise of from + k·step (0.1 + 2·0.1 = 0.30000000000000004).
double tidy(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.12g", v);
  return std::strtod(buf, nullptr);
}

std::vector<json> expand_range(const json& r, const std::string& ctx) {
  for (auto it = r.begin(); it != r.end(); ++it)
    if (it.key() != "from" && it.key() != "to" && it.key() != "step")
      throw InputError(ctx + ": unknown range field \"" + it.key() + "\" (expected from, to, step)");
  for (const char* f : {"from", "to", "step"})
    if (!r.contains(f) || !r[f].is_number()) throw InputError(ctx + ": range needs a number \"" + f + "\"");
  const double from = r["from"].get<double>(), to = r["to"].get<double>(), step = r["step"].get<double>();
  if (!std::isfinite(from) || !std::isfinite(to) || !(step > 0) || !std::isfinite(step))
    throw InputError(ctx + ": range needs finite from/to and step > 0");
  if (to < from) throw InputError(ctx + ": range has to < from");
  const bool integral = r["from"].is_number_integer() && r["to"].is_number_integer() && r["step"].is_number_integer();
  const double count = std::floor((to - from) / step + 1e-9) + 1;
  if (count > double(kMaxRangeValues)) throw InputError(ctx + ": range has more than 10000 values");
  std::vector<json> out;
  for (long k = 0; k < long(count); ++k) {
    if (integral) out.emplace_back(r["from"].get<long>() + k * r["step"].get<long>());
    else out.emplace_back(tidy(from + double(k) * step));
  }
  return out;
}

// The values of one key: a scalar, a list of scalars or a range object.
std::vector<json> key_values(const json& v, const std::string& ctx, bool valued) {
  std::vector<json> raw;
  if (v.is_array()) {
    if (v.empty()) throw InputError(ctx + ": empty list");
    for (const auto& e : v) raw.push_back(e);
  } else if (v.is_object()) {
    raw = expand_range(v, ctx);
  } else {
    raw.push_back(v);
  }
  std::vector<json> out;
  for (const json& e : raw) {
    if (valued) {
      if (e.is_number_float() && !std::isfinite(e.get<double>())) throw InputError(ctx + ": value is not finite");
      if (!e.is_string() && !e.is_number()) throw InputError(ctx + ": expected a string or a number, got " + e.dump());
    } else if (!e.is_boolean()) {
      throw InputError(ctx + ": a flag takes true or false, got " + e.dump());
    }
    if (std::find(out.begin(), out.end(), e) == out.end()) out.push_back(e);
  }
  return out;
}

std::string arg_text(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

// The settings a converged reference depends on: what `fovea render --reference SPP` would
// render (its defaults when a setting is not swept).
SharedInput reference_input(const json& settings) {
  SharedInput s;
  s.settings = {{"kind", "reference"}, {"spp", settings["reference"]}};
  for (const char* k : {"scene", "display", "reference-error"})
    if (settings.contains(k)) s.settings[k] = settings[k];
  // The render's light transport (docs/metrics.md, "What is compared with what"): its
  // --bounces, else the frame's default; auto is the reference's own default.
  const json bounces = settings.contains("bounces") ? settings["bounces"] : json(pipeline::Bounces{}.count);
  s.settings["bounces"] = bounces;
  s.id = settings_id(s.settings);
  s.out = "shared/" + s.id;
  const long spp = settings["reference"].get<long>();
  for (const char* eye : {"left", "right"}) {
    std::vector<std::string> a = {"fovea", "reference"};
    for (const char* k : {"scene", "display"})
      if (settings.contains(k)) a.insert(a.end(), {std::string("--") + k, arg_text(settings[k])});
    // The same settings as `fovea render --reference SPP`, so the images are the ones it
    // computes (and shares its cache entries).
    const std::string error = settings.contains("reference-error") ? arg_text(settings["reference-error"]) : "0.02";
    a.insert(a.end(), {"--eye", eye, "--spp", std::to_string(spp), "--until-pixel-rel-error", error});
    if (arg_text(bounces) != "auto") a.insert(a.end(), {"--bounces", arg_text(bounces), "--rr-start", "1000"});
    // Where it is cached does not change the image: not part of the id.
    if (settings.contains("reference-cache")) a.insert(a.end(), {"--reference-cache", arg_text(settings["reference-cache"])});
    a.insert(a.end(), {"--out", s.out + "/reference_" + eye + ".exr", "--quiet"});
    s.commands.push_back(std::move(a));
  }
  return s;
}

}  // namespace

const SharedInput* Plan::find_shared(const std::string& id) const {
  for (const auto& s : shared)
    if (s.id == id) return &s;
  return nullptr;
}

std::vector<RenderOption> parse_help_options(const std::string& help) {
  // An option's line: "  --name" (a lower-case letter or digit, then those and '-'), then
  // " VALUE" (the option takes one), or two spaces or the line's end (a flag).
  const auto name_char = [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-'; };
  std::vector<RenderOption> out;
  std::istringstream in(help);
  std::string l;
  while (std::getline(in, l)) {
    if (!l.starts_with("  --") || l.size() == 4 || l[4] == '-' || !name_char(l[4])) continue;
    std::size_t end = 4;
    while (end < l.size() && name_char(l[end])) ++end;
    bool takes_value = false;
    if (end < l.size()) {
      if (l[end] != ' ' || end + 1 == l.size()) continue;
      takes_value = l[end + 1] != ' ';
    }
    std::string name = l.substr(4, end - 4);
    if (name != "help") out.push_back({std::move(name), takes_value});
  }
  return out;
}

std::uint64_t fnv1a64(std::string_view bytes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::string settings_id(const json& settings) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(fnv1a64(settings.dump())));
  return buf;
}

std::string job_command(const json& settings) {
  return settings.is_object() && settings.contains("command") && settings["command"].is_string()
             ? settings["command"].get<std::string>()
             : std::string("render");
}

Plan expand_sweep(const json& sweep, const std::string& source, const std::vector<RenderOption>& render_options) {
  return expand_sweep(sweep, source, CommandOptions{{"render", render_options}});
}

Plan expand_sweep(const json& sweep, const std::string& source, const CommandOptions& options) {
  // A list of sweeps is their union (settings that only make sense together, e.g. budgets
  // for the foveated distributions and none for cartesian): jobs in list order, a job two
  // parts share once, the first part's report settings.
  if (sweep.is_array()) {
    if (sweep.empty()) throw InputError(source + ": an empty list of sweeps");
    Plan all;
    json report;
    std::set<std::string> ids;
    for (std::size_t i = 0; i < sweep.size(); ++i) {
      Plan part = expand_sweep(sweep[i], source + "[" + std::to_string(i) + "]", options);
      if (report.is_null() && !part.header["report"].empty()) report = part.header["report"];
      for (auto& s : part.shared)
        if (!all.find_shared(s.id)) all.shared.push_back(std::move(s));
      for (auto& j : part.jobs)
        if (ids.insert(j.id).second) all.jobs.push_back(std::move(j));
      if (all.jobs.size() > kMaxJobs) throw InputError(source + ": more than 100000 jobs");
    }
    all.header = {{"type", "sweep"}, {"version", 1}, {"source", source}, {"report", report.is_null() ? json::object() : report},
                  {"jobs", all.jobs.size()}, {"shared", all.shared.size()}};
    return all;
  }
  if (!sweep.is_object()) throw InputError(source + ": a sweep file is a JSON object or a list of them");
  // The command this part's jobs run: its options are the keys the part may set.
  std::string command = "render";
  if (sweep.contains("command")) {
    const json& c = sweep["command"];
    if (!c.is_string() || !options.count(c.get<std::string>())) {
      std::string names;
      for (const auto& [name, o] : options) names += (names.empty() ? "" : ", ") + name;
      throw InputError(where(source, "command") + ": expected one command name (" + names + "), got " + c.dump());
    }
    command = c.get<std::string>();
  }
  const auto command_options = options.find(command);
  if (command_options == options.end()) throw InputError(source + ": this program cannot plan `fovea " + command + "` jobs");
  std::map<std::string, bool> known;  // option -> valued
  for (const auto& o : command_options->second) known[o.name] = o.valued;
  Plan plan;
  json report = json::object();
  std::vector<std::pair<std::string, std::vector<json>>> axes;  // sorted by option name
  std::map<std::string, std::string> seen;                     // option -> the key that set it
  for (auto it = sweep.begin(); it != sweep.end(); ++it) {
    const std::string& key = it.key();
    if (key == "command") continue;
    if (key == "report") {
      if (!it->is_object()) throw InputError(where(source, key) + ": expected an object");
      static const std::set<std::string> fields = {"quality",         "time",    "group",           "budget",
                                                   "section",         "bands",   "latency",         "latency_quality",
                                                   "latency_group",   "lower_is_better", "higher_is_better",
                                                   "speedup",         "repeat"};
      for (auto f = it->begin(); f != it->end(); ++f)
        if (!fields.count(f.key())) {
          std::string names;
          for (const auto& n : fields) names += (names.empty() ? "" : ", ") + n;
          throw InputError(where(source, "report." + f.key()) + ": unknown key (expected " + names + ")");
        }
      report = *it;
      continue;
    }
    const auto alias = kAliases.find(key);
    const std::string option = alias != kAliases.end() ? alias->second : key;
    if (kReserved.count(option)) throw InputError(where(source, key) + ": set by the sweep itself, remove it");
    const auto k = known.find(option);
    if (k == known.end())
      throw InputError(where(source, key) + ": unknown key (expected scenes, displays, command, report or a `fovea " +
                       command + "` option)");
    if (!seen.emplace(option, key).second)
      throw InputError(where(source, key) + ": sets --" + option + " already set by \"" + seen[option] + "\"");
    axes.emplace_back(option, key_values(*it, where(source, key), k->second));
  }
  std::sort(axes.begin(), axes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::size_t total = 1;
  for (const auto& a : axes) {
    total *= a.second.size();
    if (total > kMaxJobs) throw InputError(source + ": more than 100000 jobs");
  }
  for (const auto& [option, values] : axes)
    if (option == "reference")
      for (const json& v : values)
        if (!v.is_number_integer() || v.get<long>() < 0)
          throw InputError(where(source, seen[option]) + ": samples per pixel must be whole numbers >= 0");

  // Odometer over the axes, the last one fastest: a fixed, documented job order.
  std::vector<std::size_t> digit(axes.size(), 0);
  std::set<std::string> ids;
  for (std::size_t n = 0; n < total; ++n) {
    Job job;
    job.settings = json::object();
    // Render jobs carry no "command", so their ids are those of sweeps before other commands.
    if (command != "render") job.settings["command"] = command;
    for (std::size_t a = 0; a < axes.size(); ++a) {
      const json& v = axes[a].second[digit[a]];
      if (!(v.is_boolean() && !v.get<bool>())) job.settings[axes[a].first] = v;  // absent flag == false
    }
    job.id = settings_id(job.settings);
    if (!ids.insert(job.id).second) throw InputError(source + ": two jobs with the same settings " + job.settings.dump());
    job.out = "jobs/" + job.id;
    const bool shares_reference = job.settings.contains("reference") && job.settings["reference"].get<long>() > 0;
    const SharedInput reference = shares_reference ? reference_input(job.settings) : SharedInput{};
    job.argv = {"fovea", command};
    for (auto it = job.settings.begin(); it != job.settings.end(); ++it) {
      if (it.key() == "command") continue;
      job.argv.push_back("--" + it.key());
      // The job loads the shared reference instead of rendering its own.
      if (it.key() == "reference" && shares_reference) job.argv.push_back(reference.out);
      else if (!it->is_boolean()) job.argv.push_back(arg_text(*it));
    }
    // PNGs of the last frame only (the sweep keeps numbers, not films), unless asked.
    if (known.count("png-every") && !job.settings.contains("png-every")) job.argv.insert(job.argv.end(), {"--png-every", "0"});
    // A latency job measures its quality at its own settings (no injected-latency sweep of
    // its own, which would render the quality frames once per injected value), unless asked.
    if (command == "latency" && known.count("inject-latency") && !job.settings.contains("inject-latency"))
      job.argv.insert(job.argv.end(), {"--inject-latency", "0"});
    if (known.count("quiet")) job.argv.push_back("--quiet");
    job.argv.insert(job.argv.end(), {"--out", job.out});
    if (shares_reference) {
      if (!plan.find_shared(reference.id)) plan.shared.push_back(reference);
      job.shared.push_back(reference.id);
    }
    plan.jobs.push_back(std::move(job));
    for (std::size_t a = axes.size(); a-- > 0;) {
      if (++digit[a] < axes[a].second.size()) break;
      digit[a] = 0;
    }
  }
  plan.header = {{"type", "sweep"}, {"version", 1}, {"source", source}, {"report", report},
                 {"jobs", plan.jobs.size()}, {"shared", plan.shared.size()}};
  return plan;
}

Plan load_sweep_file(const std::string& path, const CommandOptions& options) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the sweep file");
  json j;
  try {
    j = core::parse_json(in);
  } catch (const json::parse_error& e) {
    throw InputError(path + ": not valid JSON (" + e.what() + ")");
  }
  return expand_sweep(j, path, options);
}

std::string plan_to_jsonl(const Plan& plan) {
  std::string out = plan.header.dump() + "\n";
  for (const auto& s : plan.shared)
    out += json{{"type", "shared"}, {"id", s.id}, {"settings", s.settings}, {"commands", s.commands}, {"out", s.out}}.dump() + "\n";
  for (const auto& j : plan.jobs)
    out += json{{"type", "job"}, {"id", j.id}, {"settings", j.settings}, {"argv", j.argv}, {"out", j.out}, {"shared", j.shared}}
               .dump() +
           "\n";
  return out;
}

Plan read_plan(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the plan");
  Plan plan;
  std::string line;
  int n = 0;
  std::set<std::string> ids;
  // A plan's relative outputs must stay inside the results directory.
  auto check_out = [&](const std::string& out, const std::string& prefix, const std::string& ctx) {
    if (out.rfind(prefix, 0) != 0 || out.find("..") != std::string::npos || out.size() <= prefix.size())
      throw InputError(ctx + ": \"out\" must be " + prefix + "<id>");
  };
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    const std::string ctx = path + ":" + std::to_string(n);
    try {
      const json j = core::parse_json(line);
      const std::string type = j.at("type");
      if (type == "sweep") {
        plan.header = j;
      } else if (type == "shared") {
        SharedInput s{j.at("id"), j.at("settings"), j.at("commands"), j.at("out")};
        check_out(s.out, "shared/", ctx);
        plan.shared.push_back(std::move(s));
      } else if (type == "job") {
        Job job{j.at("id"), j.at("settings"), j.at("argv"), j.at("out"), j.at("shared")};
        check_out(job.out, "jobs/", ctx);
        if (job.argv.empty()) throw InputError(ctx + ": empty argv");
        if (!ids.insert(job.id).second) throw InputError(ctx + ": duplicate job id " + job.id);
        for (const auto& s : job.shared)
          if (!plan.find_shared(s)) throw InputError(ctx + ": shared input " + s + " is not declared above");
        plan.jobs.push_back(std::move(job));
      } else {
        throw InputError(ctx + ": unknown record type \"" + type + "\"");
      }
    } catch (const json::exception& e) {
      throw InputError(ctx + ": not a plan record (" + e.what() + ")");
    }
  }
  if (plan.header.is_null()) throw InputError(path + ": no sweep header line; is this a plan from `fovea sweep plan`?");
  return plan;
}

std::vector<std::size_t> shard_jobs(std::size_t job_count, int index, int count) {
  std::vector<std::size_t> out;
  for (std::size_t i = std::size_t(index); i < job_count; i += std::size_t(count)) out.push_back(i);
  return out;
}

std::pair<int, int> parse_shard(const std::string& text) {
  int i = -1, n = -1;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%d/%d%c", &i, &n, &tail) != 2 || n < 1 || i < 0 || i >= n)
    throw InputError("--shard: expected I/N with 0 <= I < N, got \"" + text + "\"");
  return {i, n};
}

}  // namespace fovea::sweep
