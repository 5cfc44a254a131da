#include "reference_cache.hpp"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"
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

json identity(const std::string& scene, const core::View& v, core::Eye eye, const ReferenceSettings& s) {
  return {{"format", kFormat},
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
}

std::string sidecar(const std::string& exr) { return fs::path(exr).replace_extension(".json").string(); }

json read_json(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw core::InputError(path + ": cannot open the reference description");
  try {
    return json::parse(in);
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
    r.result.rel_error = meta.at("rel_error").get<double>();
    r.result.pixel_rel_error = meta.at("pixel_rel_error").get<double>();
    r.result.seconds = meta.at("seconds").get<double>();
    const auto& m = meta.at("mean_rgb");
    r.result.mean_rgb = {m.at(0).get<double>(), m.at(1).get<double>(), m.at(2).get<double>()};
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

}  // namespace

ReferenceSettings reference_defaults(const renderer::Scene& scene) {
  const renderer::PathConfig a = renderer::albedo_path_config(renderer::albedo_stats(scene));
  ReferenceSettings s;
  s.bounces = a.max_bounces;
  s.rr_start = a.rr_start;
  s.until_pixel_rel_error = kDefaultPixelRelError;
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
  const json id = identity(req.scene, view, eye, req.settings);
  const std::string text = id.dump();
  const std::string key = hex64(sweep::fnv1a64(text));
  const fs::path exr = fs::path(req.cache_dir) / (key + ".exr");
  const std::string meta_path = sidecar(exr.string());
  if (!req.cache_dir.empty() && fs::exists(meta_path)) {
    // A damaged or foreign entry is reported, rendered again and replaced, never trusted.
    try {
      const json meta = read_json(meta_path);
      if (meta.value("key", "") != key || !meta.contains("identity") || meta["identity"].dump() != text)
        throw core::InputError(meta_path + ": describes another reference than its name's key " + key);
      return load(exr.string(), meta, meta_path);
    } catch (const core::InputError& e) {
      std::cerr << "warning: damaged reference cache entry, rendering it again: " << e.what() << "\n";
    }
  }
  renderer::ReferenceOptions o;
  o.path.spp = std::max<std::uint32_t>(1, std::min(req.settings.batch, req.settings.max_spp));
  o.path.max_bounces = req.settings.bounces;
  o.path.rr_start = req.settings.rr_start;
  o.max_spp = req.settings.max_spp;
  o.until_rel_error = req.settings.until_rel_error;
  o.until_pixel_rel_error = req.settings.until_pixel_rel_error;
  CachedReference r;
  r.result = renderer::render_reference(ctx, scene, view, eye, o, progress);
  r.key = key;
  r.identity = text;
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
                     {"identity", json::parse(ref.identity)},
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
  return r;
}

}  // namespace fovea::tools
