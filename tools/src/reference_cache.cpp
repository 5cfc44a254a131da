#include "reference_cache.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"
#include "fovea/shaders/embedded.hpp"
#include "sweep/plan.hpp"

#ifndef FOVEA_VERSION_STRING
#define FOVEA_VERSION_STRING "unknown"
#endif

namespace fovea::tools {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kFormat = 1;

std::string hex64(std::uint64_t h) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

// A scene file is identified by its bytes; a built-in scene by its name (its definition is
// part of the program, which the renderer digest covers only through the shaders: bump
// kFormat when a built-in scene changes).
std::string scene_digest(const std::string& scene) {
  std::error_code ec;
  if (!fs::is_regular_file(scene, ec)) return "builtin:" + scene;
  std::ifstream in(scene, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return "file:" + hex64(sweep::fnv1a64(bytes.str()));
}

// The path tracer's SPIR-V (every pt_* shader) and the program version: a changed renderer
// makes new keys.
std::string renderer_digest() {
  std::string bytes = FOVEA_VERSION_STRING;
  for (std::string_view name : shaders::names())
    if (name.rfind("pt_", 0) == 0) {
      const auto spv = shaders::find(name);
      bytes.append(name).append(reinterpret_cast<const char*>(spv.data()), spv.size());
    }
  return hex64(sweep::fnv1a64(bytes));
}

json view_identity(const core::View& v, core::Eye eye) {
  const core::Pose& p = v.pose();
  return {{"eye", eye == core::Eye::Left ? "left" : "right"},
          {"width", v.width()},
          {"height", v.height()},
          {"tan", {v.tan_left(), v.tan_right(), v.tan_up(), v.tan_down()}},
          {"position", {p.position.x, p.position.y, p.position.z}},
          {"orientation", {p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z}}};
}

// A reference of the whole view has no "window": its keys are those from before windows.
json identity(const std::string& scene, const core::View& v, core::Eye eye, const ReferenceSettings& s,
              const renderer::ReferenceWindow& window = {}) {
  json id = {{"format", kFormat},
             {"renderer", renderer_digest()},
             {"scene", scene_digest(scene)},
             {"view", view_identity(v, eye)},
             {"settings",
              {{"max_spp", s.max_spp},
               {"batch", s.batch},
               {"bounces", s.bounces},
               {"rr_start", s.rr_start},
               {"until_rel_error", s.until_rel_error},
               {"until_pixel_rel_error", s.until_pixel_rel_error}}}};
  if (!window.whole()) id["window"] = window_json(window);
  return id;
}

renderer::ReferenceWindow window_of(const json& identity) {
  renderer::ReferenceWindow w;
  if (!identity.contains("window")) return w;
  for (const json& d : identity.at("window")) {
    const json& c = d.at("centre");
    w.discs.push_back({{c.at(0).get<double>(), c.at(1).get<double>(), c.at(2).get<double>()}, d.at("radius_deg").get<double>()});
  }
  return w;
}

std::string sidecar(const std::string& exr) { return fs::path(exr).replace_extension(".json").string(); }

json read_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw core::InputError(path + ": cannot open the reference description");
  try {
    return core::parse_json(in);
  } catch (const json::exception& e) {
    throw core::InputError(path + ": not a reference description (" + e.what() + ")");
  }
}

// The image and statistics of a described reference; `where` names it in errors.
CachedReference load(const std::string& exr, const json& meta, const std::string& where) {
  CachedReference r;
  int width = 0, height = 0;
  try {
    r.key = meta.at("key").get<std::string>();
    const json& view = meta.at("identity").at("view");
    width = view.at("width").get<int>();
    height = view.at("height").get<int>();
    r.identity = meta.at("identity").dump();
    r.result.spp = meta.at("spp").get<std::uint32_t>();
    // null: a single batch, no estimate (NaN in ReferenceResult).
    const auto error = [&](const char* key) {
      const json& e = meta.at(key);
      return e.is_null() ? std::numeric_limits<double>::quiet_NaN() : e.get<double>();
    };
    r.result.rel_error = error("rel_error");
    r.result.pixel_rel_error = error("pixel_rel_error");
    r.result.seconds = meta.at("seconds").get<double>();
    const auto& m = meta.at("mean_rgb");
    r.result.mean_rgb = {m.at(0).get<double>(), m.at(1).get<double>(), m.at(2).get<double>()};
    r.window = window_of(meta.at("identity"));
  } catch (const json::exception& e) {
    throw core::InputError(where + ": not a reference description (" + e.what() + ")");
  }
  if (r.key != hex64(sweep::fnv1a64(r.identity)))
    throw core::InputError(where + ": its key does not match its recorded identity");
  r.result.image = renderer::read_exr(exr);
  if (r.result.image.width != width || r.result.image.height != height)
    throw core::InputError(exr + ": image size differs from its description");
  r.from_cache = true;
  return r;
}

// A window reference's pixels: those of its window on `view`, which its alpha must mark (1
// inside, 0 outside); a reference of the whole view is valid everywhere.
void check_coverage(CachedReference& r, const core::View& view, const std::string& where) {
  r.valid.clear();
  if (r.window.whole()) return;
  std::vector<bool> valid = renderer::window_coverage(r.window, view, where + ": window");
  for (std::size_t i = 0; i < valid.size(); ++i)
    if (r.result.image.pixels[i].w != (valid[i] ? 1.0f : 0.0f))
      throw core::InputError(where + ": the image's alpha does not mark its window's pixels (pixel " + std::to_string(i) +
                             ")");
  r.valid = std::move(valid);
}

// The cache entry `key`, when present and sound; a damaged or foreign entry is reported
// (`then`: what happens instead) and ignored, never trusted.
std::optional<CachedReference> lookup(const std::string& dir, const std::string& key, const std::string& text,
                                      const core::View& view, const char* then) {
  const fs::path exr = fs::path(dir) / (key + ".exr");
  const std::string meta_path = sidecar(exr.string());
  if (dir.empty() || !fs::exists(meta_path)) return std::nullopt;
  try {
    const json meta = read_json(meta_path);
    if (meta.value("key", "") != key || !meta.contains("identity") || meta["identity"].dump() != text)
      throw core::InputError(meta_path + ": describes another reference than its name's key " + key);
    CachedReference r = load(exr.string(), meta, meta_path);
    check_coverage(r, view, exr.string());
    return r;
  } catch (const core::InputError& e) {
    std::cerr << "warning: damaged reference cache entry, " << then << ": " << e.what() << "\n";
  }
  return std::nullopt;
}

}  // namespace

renderer::ReferenceWindow parse_window(const std::string& spec, const core::View& view, const std::string& option) {
  const auto numbers = [&](const std::string& text, std::size_t n, const std::string& disc) {
    std::vector<double> v;
    std::stringstream ss(text);
    std::string part;
    while (std::getline(ss, part, ',')) {
      char* end = nullptr;
      v.push_back(std::strtod(part.c_str(), &end));
      if (part.empty() || *end != '\0')
        throw core::InputError(option + ": \"" + part + "\" in \"" + disc + "\" is not a number");
    }
    if (v.size() != n || (!text.empty() && text.back() == ','))
      throw core::InputError(option + ": \"" + disc + "\" needs " + std::to_string(n) + " comma-separated numbers before @");
    return v;
  };
  renderer::ReferenceWindow w;
  std::stringstream ss(spec);
  std::string disc;
  while (std::getline(ss, disc, ';')) {
    const std::size_t at = disc.rfind('@');
    if (at == std::string::npos)
      throw core::InputError(option + ": \"" + disc + "\" is not X,Y,Z@RADIUS or px:X,Y@RADIUS (degrees)");
    const std::string centre = disc.substr(0, at);
    renderer::WindowDisc d;
    d.radius_deg = numbers(disc.substr(at + 1), 1, disc)[0];
    if (centre.rfind("px:", 0) == 0) {
      const auto p = numbers(centre.substr(3), 2, disc);
      d.centre = view.pixel_to_dir({p[0], p[1]});
    } else {
      const auto c = numbers(centre, 3, disc);
      d.centre = {c[0], c[1], c[2]};
    }
    w.discs.push_back(d);
  }
  if (w.discs.empty()) throw core::InputError(option + ": expected X,Y,Z@RADIUS or px:X,Y@RADIUS, got \"" + spec + "\"");
  renderer::window_coverage(w, view, option);
  return w;
}

json window_json(const renderer::ReferenceWindow& window) {
  if (window.whole()) return nullptr;
  json discs = json::array();
  for (const renderer::WindowDisc& d : window.discs) {
    const glm::dvec3 c = d.centre / glm::length(d.centre);
    discs.push_back({{"centre", {c.x, c.y, c.z}}, {"radius_deg", d.radius_deg}});
  }
  return discs;
}

ReferenceSettings reference_defaults(const renderer::Scene& scene) {
  const renderer::PathConfig a = renderer::albedo_path_config(renderer::albedo_stats(scene));
  ReferenceSettings s;
  s.bounces = a.max_bounces;
  s.rr_start = a.rr_start;
  s.until_pixel_rel_error = kDefaultPixelRelError;
  return s;
}

ReferenceSettings reference_settings(const renderer::Scene& scene, const renderer::PathConfig& transport) {
  ReferenceSettings s = reference_defaults(scene);
  s.bounces = transport.max_bounces;
  s.rr_start = transport.rr_start;
  return s;
}

std::string default_reference_cache() {
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return (fs::path(x) / "fovea" / "references").string();
  if (const char* h = std::getenv("HOME"); h && *h) return (fs::path(h) / ".cache" / "fovea" / "references").string();
  return "out/reference-cache";
}

std::string reference_cache_arg(const std::string* value) {
  if (!value) return default_reference_cache();
  if (*value == "off") return "";
  if (value->empty()) throw core::InputError("--reference-cache: expected a directory or off");
  return *value;
}

CachedReference cached_reference(gpu::Context& ctx, const renderer::GpuScene& scene, const core::View& view,
                                 core::Eye eye, const ReferenceRequest& req,
                                 const std::function<void(const renderer::ReferenceProgress&)>& progress) {
  // The window is checked before the cache is: a bad one is bad input, not a miss.
  std::vector<bool> valid = renderer::window_coverage(req.window, view, "reference window");
  const std::string text = identity(req.scene, view, eye, req.settings, req.window).dump();
  const std::string key = hex64(sweep::fnv1a64(text));
  if (auto hit = lookup(req.cache_dir, key, text, view, "rendering it again")) return std::move(*hit);
  // The whole view with the same settings holds every pixel of any window; the reverse
  // never serves.
  if (!req.window.whole()) {
    const std::string whole = identity(req.scene, view, eye, req.settings).dump();
    if (auto hit = lookup(req.cache_dir, hex64(sweep::fnv1a64(whole)), whole, view, "rendering the window instead"))
      return std::move(*hit);
  }
  const fs::path exr = fs::path(req.cache_dir) / (key + ".exr");
  renderer::ReferenceOptions o;
  o.path.spp = std::max<std::uint32_t>(1, std::min(req.settings.batch, req.settings.max_spp));
  o.path.max_bounces = req.settings.bounces;
  o.path.rr_start = req.settings.rr_start;
  o.max_spp = req.settings.max_spp;
  o.until_rel_error = req.settings.until_rel_error;
  o.until_pixel_rel_error = req.settings.until_pixel_rel_error;
  o.window = req.window;
  CachedReference r;
  r.result = renderer::render_reference(ctx, scene, view, eye, o, progress);
  if (std::isnan(r.result.pixel_rel_error))
    std::cerr << "warning: reference: " << r.result.spp << " spp is a single batch of " << o.path.spp
              << ": its error cannot be estimated (rel_error and pixel_rel_error are null); at least "
              << 2 * o.path.spp << " spp (two batches) gives an estimate\n";
  r.key = key;
  r.identity = text;
  r.window = req.window;
  if (!req.window.whole()) r.valid = std::move(valid);
  if (!req.cache_dir.empty()) {
    // The reference is good without its cache entry: an unwritable cache costs the next run.
    try {
      fs::create_directories(req.cache_dir);
      write_reference(exr.string(), r);
    } catch (const std::exception& e) {
      std::cerr << "warning: reference not cached in " << req.cache_dir << ": " << e.what() << "\n";
    }
  }
  return r;
}

void write_reference(const std::string& exr, const CachedReference& ref) {
  renderer::write_exr(exr, ref.result.image);
  const auto& r = ref.result;
  const json meta = {{"format", "fovea-reference"},
                     {"key", ref.key},
                     {"identity", core::parse_json(ref.identity)},
                     {"image", fs::path(exr).filename().string()},
                     {"spp", r.spp},
                     {"rel_error", r.rel_error},
                     {"pixel_rel_error", r.pixel_rel_error},
                     {"mean_rgb", {r.mean_rgb.x, r.mean_rgb.y, r.mean_rgb.z}},
                     {"seconds", r.seconds}};
  core::write_file_atomic(sidecar(exr), meta.dump(2) + "\n");
}

CachedReference read_reference(const std::string& exr, const std::string& scene, const core::View& view, core::Eye eye) {
  const std::string meta_path = sidecar(exr);
  const json meta = read_json(meta_path);
  CachedReference r = load(exr, meta, meta_path);
  const json want = identity(scene, view, eye, {});
  const json& have = meta["identity"];
  for (const char* part : {"scene", "view"})
    if (have.value(part, json()) != want[part])
      throw core::InputError(meta_path + ": a reference of another " + part + " (" + have.value(part, json()).dump() +
                             ", this render needs " + want[part].dump() + ")");
  check_coverage(r, view, exr);
  return r;
}

}  // namespace fovea::tools
