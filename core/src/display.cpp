#include "fovea/core/display.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "fovea/core/input_limits.hpp"
#include "fovea/core/lens.hpp"
#include "json_input.hpp"

namespace fovea::core {

namespace embedded_displays {
std::span<const std::uint8_t> find(std::string_view name);
std::vector<std::string_view> names();
}  // namespace embedded_displays

namespace {

using nlohmann::json;

[[noreturn]] void fail(std::string_view origin, const std::string& what) {
  throw InputError(std::string(origin) + ": " + what);
}

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

double number(const json& j, const char* key, std::string_view origin, const std::string& path) {
  if (!j.contains(key) || !j[key].is_number()) fail(origin, "missing or non-numeric \"" + path + key + "\"");
  const double v = j[key].get<double>();
  if (!std::isfinite(v)) fail(origin, "non-finite \"" + path + key + "\"");
  return v;
}

// An optional string member; anything but a string is an error naming the key.
std::string string_member(const json& j, const char* key, std::string_view origin) {
  if (!j.contains(key)) return {};
  if (!j[key].is_string()) fail(origin, "\"" + std::string(key) + "\" must be a string");
  return j[key].get<std::string>();
}

Fov read_fov(const json& j, std::string_view origin, const std::string& path) {
  if (!j.is_object()) fail(origin, "\"" + path + "\" must be an object");
  const std::string p = path + ".";
  return Fov::from_degrees(number(j, "left", origin, p), number(j, "right", origin, p),
                           number(j, "up", origin, p), number(j, "down", origin, p));
}

}  // namespace

DisplayPreset parse_display(std::string_view text, std::string_view origin) {
  const json j = detail::parse_json_input(text, origin);
  if (!j.is_object()) fail(origin, "top level must be an object");
  DisplayPreset d;
  d.json = std::string(text);
  d.origin = std::string(origin);
  d.name = string_member(j, "name", origin);
  if (d.name.empty()) fail(origin, "missing \"name\"");
  d.description = string_member(j, "description", origin);
  const double w = number(j, "width", origin, ""), h = number(j, "height", origin, "");
  const std::string max_px = std::to_string(kMaxEyePixels);
  if (w < 1 || w > kMaxEyePixels || w != std::floor(w))
    fail(origin, "\"width\" must be a whole number of pixels in 1.." + max_px + " (per eye)");
  if (h < 1 || h > kMaxEyePixels || h != std::floor(h))
    fail(origin, "\"height\" must be a whole number of pixels in 1.." + max_px + " (per eye)");
  d.width = static_cast<int>(w);
  d.height = static_cast<int>(h);
  if (!j.contains("fov_deg")) fail(origin, "missing \"fov_deg\"");
  d.fov_left = read_fov(j["fov_deg"], origin, "fov_deg");
  d.fov_right = j.contains("fov_deg_right") ? read_fov(j["fov_deg_right"], origin, "fov_deg_right")
                                            : d.fov_left.mirrored();
  if (j.contains("refresh_hz")) d.refresh_hz = number(j, "refresh_hz", origin, "");
  if (j.contains("ipd_m")) d.ipd_m = number(j, "ipd_m", origin, "");
  if (j.contains("cant_deg")) d.cant_deg = number(j, "cant_deg", origin, "");
  d.lens = parse_lens_params(text, origin);
  if (!(d.refresh_hz >= kMinRefreshHz && d.refresh_hz <= kMaxRefreshHz))
    fail(origin, "\"refresh_hz\" must be in [" + fmt(kMinRefreshHz) + ", " + fmt(kMaxRefreshHz) + "] Hz");
  // A negative IPD swaps the eyes, a huge one puts them outside any scene.
  if (!(d.ipd_m >= 0 && d.ipd_m <= kMaxIpdM))
    fail(origin, "\"ipd_m\" must be in [0, " + fmt(kMaxIpdM) + "] m");
  if (!(d.cant_deg >= 0 && d.cant_deg <= kMaxCantDeg))
    fail(origin, "\"cant_deg\" must be in [0, " + fmt(kMaxCantDeg) + "] degrees");
  try {  // validates the FOV and raster
    (void)d.view(Eye::Left);
    (void)d.view(Eye::Right);
  } catch (const InputError& e) {
    fail(origin, e.what());
  }
  // The optics depend on the FOV only (uv space), so they are checked here, whatever uses them.
  for (Eye e : {Eye::Left, Eye::Right}) (void)Lens::for_eye(d, e);
  return d;
}

DisplayPreset load_display(std::string_view name_or_path) {
  const auto bytes = embedded_displays::find(std::string(name_or_path) + ".json");
  if (!bytes.empty())
    return parse_display(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                         name_or_path);
  const std::filesystem::path path(name_or_path);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    std::string names;
    for (const auto& n : display_preset_names()) names += (names.empty() ? "" : ", ") + n;
    throw InputError("display \"" + std::string(name_or_path) +
                     "\": neither a preset name (" + names + ") nor a readable file");
  }
  // A preset is a few hundred bytes; the bound keeps a wrong path (a log, a device) harmless.
  return parse_display(read_file_bounded(path.string(), 1 << 20), path.string());
}

std::vector<std::string> display_preset_names() {
  std::vector<std::string> out;
  for (auto n : embedded_displays::names()) {
    std::string s(n);
    if (s.size() > 5 && s.ends_with(".json")) out.push_back(s.substr(0, s.size() - 5));
  }
  return out;
}

Eye parse_eye(std::string_view s) {
  if (s == "left") return Eye::Left;
  if (s == "right") return Eye::Right;
  throw InputError("eye: expected left or right, got \"" + std::string(s) + "\"");
}

const char* eye_name(Eye e) { return e == Eye::Left ? "left" : "right"; }

}  // namespace fovea::core
