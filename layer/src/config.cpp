#include "config.hpp"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "fovea/core/input_limits.hpp"
#include "fovea/core/json.hpp"

namespace fovea::layer {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? v : "";
}

// One of two words: true for `yes`, false for `no`; anything else names `where`.
bool parse_either(const std::string& v, const std::string& where, const char* yes, const char* no) {
  if (v == yes) return true;
  if (v == no) return false;
  throw core::InputError(where + ": \"" + v + "\" must be \"" + yes + "\" or \"" + no + "\"");
}

bool parse_render_mode(const std::string& v, const std::string& where) {
  return parse_either(v, where, "lockstep", "async");
}

bool parse_compositor(const std::string& v, const std::string& where) { return parse_either(v, where, "gpu", "host"); }

bool parse_handover(const std::string& v, const std::string& where) { return parse_either(v, where, "shared", "host"); }

RenderPriority parse_render_priority(const std::string& v, const std::string& where) {
  if (v == "idle") return {true, 19};
  // A whole number 0..19 (no sign, no spaces): nice values below the default are not the layer's to take.
  if (!v.empty() && v.size() <= 2 && v.find_first_not_of("0123456789") == std::string::npos && std::stoi(v) <= 19)
    return {false, std::stoi(v)};
  throw core::InputError(where + ": \"" + v + "\" must be \"idle\" or a nice value 0..19");
}

void apply_section(const nlohmann::json& s, const std::string& where, LayerConfig& c) {
  if (!s.is_object()) throw core::InputError(where + ": must be an object");
  for (const auto& [key, v] : s.items()) {
    const std::string field = where + "." + key;
    if (key == "scene" || key == "gaze") {
      if (!v.is_string()) throw core::InputError(field + ": must be a string");
      (key == "scene" ? c.scene : c.gaze) = v.get<std::string>();
      if (key == "scene") c.origin = where;
    } else if (key == "composite") {
      const std::string m = v.is_string() ? v.get<std::string>() : "";
      if (m == "app-on-top") c.composite = Composite::AppOnTop;
      else if (m == "alpha") c.composite = Composite::Alpha;
      else if (m == "scene-only") c.composite = Composite::SceneOnly;
      else throw core::InputError(field + ": must be \"app-on-top\", \"alpha\" or \"scene-only\"");
    } else if (key == "compositor") {
      c.gpu_compositor = parse_compositor(v.is_string() ? v.get<std::string>() : v.dump(), field);
    } else if (key == "handover") {
      c.shared_handover = parse_handover(v.is_string() ? v.get<std::string>() : v.dump(), field);
    } else if (key == "render_priority") {
      c.render_priority = parse_render_priority(v.is_string() ? v.get<std::string>() : v.dump(), field);
    } else if (key == "render") {
      c.lockstep = parse_render_mode(v.is_string() ? v.get<std::string>() : v.dump(), field);
    } else if (key == "app_background") {
      if (v.is_string() && v.get<std::string>() == "auto") {
        c.app_background.reset();
        continue;
      }
      if (!v.is_array() || v.size() != 3) throw core::InputError(field + ": must be \"auto\" or [r, g, b] (0..255)");
      std::array<int, 3> rgb{};
      for (int i = 0; i < 3; ++i) {
        // Range-checked in 64 bits: get<int>() would wrap 4294967297 to 1.
        const bool in_range = v[i].is_number_unsigned() ? v[i].get<std::uint64_t>() <= 255
                              : v[i].is_number_integer() ? v[i].get<std::int64_t>() >= 0 && v[i].get<std::int64_t>() <= 255
                                                         : false;
        if (!in_range)
          throw core::InputError(field + "[" + std::to_string(i) + "]: " + v[i].dump() +
                                 " is not a whole number in 0..255 (expected \"auto\" or [r, g, b])");
        rgb[i] = static_cast<int>(v[i].get<std::int64_t>());
      }
      c.app_background = rgb;
    } else if (const auto& names = pipeline::frame_option_names(); std::find(names.begin(), names.end(), key) != names.end()) {
      pipeline::apply_frame_option(c.frame, key, v.is_string() ? v.get<std::string>() : v.dump(), field);
      c.budget_given |= key == "budget";
    } else {
      std::string known = "scene, composite, app_background, gaze, render, compositor, render_priority";
      for (const std::string& n : pipeline::frame_option_names()) known += ", " + n;
      throw core::InputError(field + ": unknown key (" + known + ")");
    }
  }
}

// The frame options' joint checks (Cartesian's budget, the budget's range), naming `origin`.
void finish_frame(LayerConfig& c, const std::string& origin) {
  try {
    pipeline::finish(c.frame, c.budget_given);
  } catch (const core::InputError& e) {
    throw core::InputError(origin + ": " + e.what());
  }
}

}  // namespace

std::string render_priority_name(const RenderPriority& p) {
  return p.idle ? "SCHED_IDLE" : "nice " + std::to_string(p.nice);
}

const char* composite_name(Composite c) {
  switch (c) {
    case Composite::AppOnTop: return "app-on-top";
    case Composite::Alpha: return "alpha";
    case Composite::SceneOnly: return "scene-only";
  }
  return "?";
}

namespace {
// The file's sections over the defaults, the frame options not yet finished (the environment
// may still change them).
LayerConfig parse_sections(const std::string& text, const std::string& origin, const std::string& application) {
  nlohmann::json j;
  try {
    j = core::parse_json(text);
  } catch (const nlohmann::json::exception& e) {
    throw core::InputError(origin + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) throw core::InputError(origin + ": must be a JSON object");
  LayerConfig c;
  for (const auto& [key, v] : j.items())
    if (key != "default" && key != "applications")
      throw core::InputError(origin + ": unknown key \"" + key + "\" (default, applications)");
  if (j.contains("default")) apply_section(j["default"], origin + ": default", c);
  if (j.contains("applications")) {
    const auto& apps = j["applications"];
    if (!apps.is_object()) throw core::InputError(origin + ": applications: must be an object");
    if (apps.contains(application)) apply_section(apps[application], origin + ": applications." + application, c);
  }
  return c;
}
}  // namespace

LayerConfig parse_config(const std::string& text, const std::string& origin, const std::string& application) {
  LayerConfig c = parse_sections(text, origin, application);
  finish_frame(c, origin);
  return c;
}

LayerConfig load_config(const std::string& application) {
  namespace fs = std::filesystem;
  LayerConfig c;
  fs::path dir = env("XDG_CONFIG_HOME");
  if (dir.empty() && !env("HOME").empty()) dir = fs::path(env("HOME")) / ".config";
  const fs::path file = dir / "fovea" / "layer.json";
  std::error_code ec;
  if (!dir.empty() && fs::is_regular_file(file, ec)) {
    c = parse_sections(core::read_file_bounded(file.string(), 1 << 20), file.string(), application);
  }
  for (const char* name : {"FOVEA_LAYER_SCENE", "FOVEA_SCENE"})
    if (!env(name).empty()) {
      c.scene = env(name);
      c.origin = name;
    }
  if (!env("FOVEA_GAZE").empty()) c.gaze = env("FOVEA_GAZE");
  if (!env("FOVEA_LAYER_RENDER").empty()) c.lockstep = parse_render_mode(env("FOVEA_LAYER_RENDER"), "FOVEA_LAYER_RENDER");
  if (!env("FOVEA_LAYER_COMPOSITOR").empty())
    c.gpu_compositor = parse_compositor(env("FOVEA_LAYER_COMPOSITOR"), "FOVEA_LAYER_COMPOSITOR");
  if (!env("FOVEA_LAYER_HANDOVER").empty())
    c.shared_handover = parse_handover(env("FOVEA_LAYER_HANDOVER"), "FOVEA_LAYER_HANDOVER");
  if (!env("FOVEA_LAYER_RENDER_PRIORITY").empty())
    c.render_priority = parse_render_priority(env("FOVEA_LAYER_RENDER_PRIORITY"), "FOVEA_LAYER_RENDER_PRIORITY");
  for (const std::string& name : pipeline::frame_option_names()) {
    std::string var = "FOVEA_LAYER_" + name;
    for (char& ch : var) ch = ch == '-' ? '_' : char(std::toupper(static_cast<unsigned char>(ch)));
    if (env(var.c_str()).empty()) continue;
    pipeline::apply_frame_option(c.frame, name, env(var.c_str()), var);
    c.budget_given |= name == "budget";
  }
  finish_frame(c, "the layer's configuration");
  return c;
}

}  // namespace fovea::layer
