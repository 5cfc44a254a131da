#include "fovea/xrcommon/timing_record.hpp"

#include <cmath>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "fovea/core/json.hpp"
#include "fovea/core/view.hpp"

namespace fovea::xrcommon {

using json = nlohmann::ordered_json;

namespace {

constexpr const char* kSchema = "fovea-timing";

double finite(double v) { return std::isfinite(v) ? v : 0.0; }
bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

json time_or_null(const std::optional<core::TimeNs>& t) { return t ? json(*t) : json(nullptr); }

json stages(const std::vector<std::pair<std::string, double>>& v) {
  json j = json::object();
  for (const auto& [name, ms] : v) j[name] = finite(ms);
  return j;
}

// The optional times, in the order they are written.
using TimeField = std::optional<core::TimeNs> TimingRecord::*;
constexpr std::pair<const char*, TimeField> kTimes[] = {
    {"gaze_sample_ns", &TimingRecord::gaze_sample_ns},
    {"gaze_device_ns", &TimingRecord::gaze_device_ns},
    {"gaze_receive_ns", &TimingRecord::gaze_receive_ns},
    {"gaze_read_ns", &TimingRecord::gaze_read_ns},
    {"head_pose_ns", &TimingRecord::head_pose_ns},
    {"head_pose_target_ns", &TimingRecord::head_pose_target_ns},
    {"predicted_display_ns", &TimingRecord::predicted_display_ns},
    {"wait_call_ns", &TimingRecord::wait_call_ns},
    {"wait_return_ns", &TimingRecord::wait_return_ns},
    {"begin_ns", &TimingRecord::begin_ns},
    {"end_call_ns", &TimingRecord::end_call_ns},
    {"end_return_ns", &TimingRecord::end_return_ns},
    {"submit_ns", &TimingRecord::submit_ns},
    {"vsync_ns", &TimingRecord::vsync_ns},
};

json photons(const PhotonTimes& p) { return {{"start", p.start}, {"mid", p.mid}, {"end", p.end}}; }

}  // namespace

const char* time_base_name(TimeBase b) { return b == TimeBase::Monotonic ? "monotonic" : "virtual"; }

std::optional<double> TimingRecord::foveal_error_deg() const {
  if (!fovea_dir || !true_gaze_dir) return std::nullopt;
  const double deg = core::angle_deg(*fovea_dir, *true_gaze_dir);
  return std::isfinite(deg) ? std::optional<double>(deg) : std::nullopt;
}

void TimingRecord::set_gaze_times(core::TimeNs sample, core::TimeNs receive, core::TimeNs read) {
  const auto known = [](core::TimeNs v) { return v ? std::optional<core::TimeNs>(v) : std::nullopt; };
  gaze_sample_ns = known(sample);
  gaze_receive_ns = known(receive);
  gaze_read_ns = known(read);
}

void TimingRecord::set_frame_calls(core::TimeNs wait_call, core::TimeNs wait_return, core::TimeNs begin,
                                   core::TimeNs end_call, core::TimeNs end_return) {
  wait_call_ns = wait_call;
  wait_return_ns = wait_return;
  begin_ns = begin;
  end_call_ns = end_call;
  end_return_ns = end_return;
}

std::string to_json_line(const TimingRecord& r) {
  json j;
  j["schema"] = kSchema;
  j["version"] = kTimingVersion;
  j["source"] = r.source;
  j["clock"] = time_base_name(r.clock);
  j["frame"] = r.frame;
  j["session"] = r.session ? json(*r.session) : json(nullptr);
  j["gaze_valid"] = r.gaze_valid;
  for (const auto& [key, field] : kTimes) j[key] = time_or_null(r.*field);
  j["missed_vsyncs"] = r.missed_vsyncs;
  j["photon_ns"] = r.photon_ns ? json{{"left", photons((*r.photon_ns)[0])}, {"right", photons((*r.photon_ns)[1])}}
                               : json(nullptr);
  j["cpu_ms"] = stages(r.cpu_ms);
  j["gpu_ms"] = stages(r.gpu_ms);
  const auto dir = [](const std::optional<glm::dvec3>& d) {
    return d && finite(*d) ? json{d->x, d->y, d->z} : json(nullptr);
  };
  j["fovea_dir"] = dir(r.fovea_dir);
  j["true_gaze_dir"] = dir(r.true_gaze_dir);
  const std::optional<double> err = r.foveal_error_deg();
  j["foveal_error_deg"] = err ? json(*err) : json(nullptr);
  for (const auto& [key, v] : r.extra) {
    if (const auto* d = std::get_if<double>(&v))
      j[key] = finite(*d);
    else
      std::visit([&, k = key](const auto& x) { j[k] = x; }, v);
  }
  return j.dump() + "\n";
}

TimingRecord parse_timing_record(std::string_view line, const std::string& where) {
  json j;
  try {
    j = core::parse_json(line);
  } catch (const json::exception& e) {
    throw core::InputError(where + ": not JSON: " + e.what());
  }
  if (!j.is_object() || j.value("schema", "") != kSchema)
    throw core::InputError(where + ": not a timing record (\"schema\": \"" + std::string(kSchema) + "\" missing)");
  if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<int>() != kTimingVersion)
    throw core::InputError(where + ": timing record version " + (j.contains("version") ? j["version"].dump() : "missing") +
                           ", this build reads version " + std::to_string(kTimingVersion));
  TimingRecord r;
  try {
    r.source = j.at("source").get<std::string>();
    const std::string clock = j.at("clock").get<std::string>();
    if (clock != "monotonic" && clock != "virtual") throw core::InputError(where + ": clock \"" + clock + "\": expected monotonic or virtual");
    r.clock = clock == "monotonic" ? TimeBase::Monotonic : TimeBase::Virtual;
    r.frame = j.at("frame").get<std::int64_t>();
    if (j.contains("session") && !j["session"].is_null()) r.session = j["session"].get<std::int64_t>();
    r.gaze_valid = j.value("gaze_valid", false);
    for (const auto& [key, field] : kTimes)
      if (j.contains(key) && !j[key].is_null()) r.*field = j[key].get<core::TimeNs>();
    r.missed_vsyncs = j.value("missed_vsyncs", std::int64_t(0));
    if (j.contains("photon_ns") && !j["photon_ns"].is_null()) {
      std::array<PhotonTimes, 2> p;
      for (int e = 0; e < 2; ++e) {
        const json& pe = j["photon_ns"].at(e == 0 ? "left" : "right");
        p[e] = {pe.at("start").get<core::TimeNs>(), pe.at("mid").get<core::TimeNs>(), pe.at("end").get<core::TimeNs>()};
      }
      r.photon_ns = p;
    }
    for (auto [key, out] : {std::pair{"cpu_ms", &r.cpu_ms}, {"gpu_ms", &r.gpu_ms}})
      if (j.contains(key))
        for (const auto& [name, v] : j[key].items()) out->emplace_back(name, v.get<double>());
    const auto dir = [&](const char* key, std::optional<glm::dvec3>& out) {
      if (!j.contains(key) || j[key].is_null()) return;
      const json& d = j[key];
      if (!d.is_array() || d.size() != 3) throw core::InputError(where + ": " + key + ": expected [x, y, z]");
      out = glm::dvec3(d[0].get<double>(), d[1].get<double>(), d[2].get<double>());
      if (glm::length(*out) == 0) throw core::InputError(where + ": " + key + ": zero direction");
    };
    dir("fovea_dir", r.fovea_dir);
    dir("true_gaze_dir", r.true_gaze_dir);
  } catch (const json::exception& e) {
    throw core::InputError(where + ": bad timing record: " + e.what());
  }
  return r;
}

}  // namespace fovea::xrcommon
