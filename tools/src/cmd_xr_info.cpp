// fovea xr-info: what the OpenXR loader sees — the active runtime, the API layers — and
// whether the Fovea runtime and the Fovea layer load. The loader is opened at run time
// (dlopen), so the CLI works, and says so, on machines without OpenXR.
#include <dlfcn.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#define XR_NO_PROTOTYPES
#include <openxr/openxr.h>
#include <openxr/openxr_reflection.h>

#include "command.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/json.hpp"

namespace fovea::tools {
namespace {

constexpr const char* kFoveaLayer = "XR_APILAYER_FOVEA_path_tracing";
constexpr const char* kFoveaRuntimeName = "Fovea simulated HMD";

struct Loader {
  void* lib = nullptr;
  PFN_xrGetInstanceProcAddr gipa = nullptr;
  PFN_xrEnumerateApiLayerProperties enumerate_layers = nullptr;
  PFN_xrCreateInstance create = nullptr;
  ~Loader() {
    if (lib) dlclose(lib);
  }
};

std::string result_name(XrResult r) {
  switch (r) {
#define FOVEA_CASE(n, v) \
  case n:                \
    return #n;
    XR_LIST_ENUM_XrResult(FOVEA_CASE)
#undef FOVEA_CASE
    default: return "XrResult " + std::to_string(int(r));
  }
}

// The runtime manifest the 1.0.x loader picks on Linux: XR_RUNTIME_JSON, else the first
// openxr/1/active_runtime.json under $XDG_CONFIG_HOME, $XDG_CONFIG_DIRS (/etc/xdg), /etc.
nlohmann::json active_runtime_manifest() {
  nlohmann::json j;
  std::vector<std::pair<std::string, std::string>> candidates;
  if (const char* env = std::getenv("XR_RUNTIME_JSON"); env && *env) {
    candidates.emplace_back(env, "XR_RUNTIME_JSON");
  } else {
    const char* home = std::getenv("HOME");
    const char* xch = std::getenv("XDG_CONFIG_HOME");
    if (xch && *xch)
      candidates.emplace_back(std::string(xch) + "/openxr/1/active_runtime.json", "XDG_CONFIG_HOME");
    else if (home)
      candidates.emplace_back(std::string(home) + "/.config/openxr/1/active_runtime.json", "XDG_CONFIG_HOME");
    const char* xcd = std::getenv("XDG_CONFIG_DIRS");
    std::stringstream dirs(xcd && *xcd ? xcd : "/etc/xdg");
    for (std::string d; std::getline(dirs, d, ':');)
      if (!d.empty()) candidates.emplace_back(d + "/openxr/1/active_runtime.json", "XDG_CONFIG_DIRS");
    candidates.emplace_back("/etc/openxr/1/active_runtime.json", "/etc");
  }
  for (const auto& [path, source] : candidates) {
    if (!std::filesystem::exists(path)) continue;
    j["path"] = path;
    j["source"] = source;
    try {
      std::ifstream in(path);
      const auto m = core::parse_json(in);
      j["library_path"] = m.at("runtime").at("library_path");
      if (m["runtime"].contains("name")) j["name"] = m["runtime"]["name"];
    } catch (const std::exception& e) {
      j["error"] = std::string("unreadable manifest: ") + e.what();
    }
    return j;
  }
  j["error"] = "no runtime manifest found";
  return j;
}

// Creates (and destroys) an instance, optionally with one API layer enabled.
nlohmann::json try_instance(const Loader& l, const char* layer) {
  nlohmann::json j;
  XrInstanceCreateInfo ci{XR_TYPE_INSTANCE_CREATE_INFO};
  std::strcpy(ci.applicationInfo.applicationName, "fovea xr-info");
  ci.applicationInfo.apiVersion = XR_CURRENT_API_VERSION;
  ci.enabledApiLayerCount = layer ? 1 : 0;
  ci.enabledApiLayerNames = &layer;
  XrInstance inst = XR_NULL_HANDLE;
  const XrResult r = l.create(&ci, &inst);
  j["loads"] = XR_SUCCEEDED(r);
  j["result"] = result_name(r);
  if (XR_FAILED(r)) return j;
  auto get = [&](const char* name) {
    PFN_xrVoidFunction fn = nullptr;
    l.gipa(inst, name, &fn);
    return fn;
  };
  XrInstanceProperties props{XR_TYPE_INSTANCE_PROPERTIES};
  if (auto fn = reinterpret_cast<PFN_xrGetInstanceProperties>(get("xrGetInstanceProperties"));
      fn && XR_SUCCEEDED(fn(inst, &props))) {
    j["runtime_name"] = props.runtimeName;
    j["runtime_version"] = std::to_string(XR_VERSION_MAJOR(props.runtimeVersion)) + "." +
                           std::to_string(XR_VERSION_MINOR(props.runtimeVersion)) + "." +
                           std::to_string(XR_VERSION_PATCH(props.runtimeVersion));
    j["is_fovea"] = std::string(props.runtimeName) == kFoveaRuntimeName;
  }
  XrSystemGetInfo gi{XR_TYPE_SYSTEM_GET_INFO};
  gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  XrSystemId sys = XR_NULL_SYSTEM_ID;
  auto get_system = reinterpret_cast<PFN_xrGetSystem>(get("xrGetSystem"));
  auto get_props = reinterpret_cast<PFN_xrGetSystemProperties>(get("xrGetSystemProperties"));
  if (get_system && get_props && XR_SUCCEEDED(get_system(inst, &gi, &sys))) {
    XrSystemProperties sp{XR_TYPE_SYSTEM_PROPERTIES};
    if (XR_SUCCEEDED(get_props(inst, sys, &sp))) j["system_name"] = sp.systemName;
  }
  if (auto destroy = reinterpret_cast<PFN_xrDestroyInstance>(get("xrDestroyInstance"))) destroy(inst);
  return j;
}

void print_text(const nlohmann::json& j) {
  std::cout << "loader:  " << j["loader"].get<std::string>() << "\n";
  const auto& m = j["runtime_manifest"];
  std::cout << "runtime manifest: "
            << (m.contains("path") ? m["path"].get<std::string>() + " (from " + m["source"].get<std::string>() + ")"
                                   : std::string("-"))
            << "\n";
  if (m.contains("library_path")) std::cout << "  library: " << m["library_path"].get<std::string>() << "\n";
  if (m.contains("error")) std::cout << "  " << m["error"].get<std::string>() << "\n";
  const auto& r = j["runtime"];
  std::cout << "runtime: " << (r["loads"].get<bool>() ? "loads" : "does not load") << " ("
            << r["result"].get<std::string>() << ")";
  if (r.contains("runtime_name"))
    std::cout << ", \"" << r["runtime_name"].get<std::string>() << "\" " << r["runtime_version"].get<std::string>()
              << (r["is_fovea"].get<bool>() ? " [Fovea]" : "");
  if (r.contains("system_name")) std::cout << ", system \"" << r["system_name"].get<std::string>() << "\"";
  std::cout << "\napi layers (" << j["layers"].size() << "):\n";
  for (const auto& l : j["layers"])
    std::cout << "  " << l["name"].get<std::string>() << " v" << l["layer_version"].get<std::uint32_t>() << "  "
              << l["description"].get<std::string>() << "\n";
  const auto& f = j["fovea_layer"];
  std::cout << "fovea layer " << kFoveaLayer << ": "
            << (!f["found"].get<bool>() ? "not found (set XR_API_LAYER_PATH to its manifest's directory)"
                : f["loads"].get<bool>() ? "loads"
                                         : "found, does not load (" + f["result"].get<std::string>() + ")")
            << "\n";
}

int run(std::vector<std::string> argv) {
  const Args args(argv, {"runtime-json", "layer-path"}, {"json", "help"});
  if (args.has("help")) {
    std::cout << "usage: fovea xr-info [--json] [--runtime-json FILE] [--layer-path DIR]\n"
                 "  Reports the OpenXR runtime the loader selects, the API layers it finds, and whether\n"
                 "  the runtime and the Fovea layer (" << kFoveaLayer << ") load.\n"
                 "  --runtime-json FILE  use this runtime manifest (as XR_RUNTIME_JSON)\n"
                 "  --layer-path DIR     search explicit layer manifests here (as XR_API_LAYER_PATH)\n"
                 "  --json               machine-readable output\n"
                 "  Exit status: 0 when the runtime loads, 1 when no runtime loads (or no loader), 2 on\n"
                 "  invalid arguments.\n";
    return 0;
  }
  if (auto p = args.opt("runtime-json")) {
    if (!std::filesystem::exists(*p)) throw core::InputError("--runtime-json " + *p + ": no such file");
    setenv("XR_RUNTIME_JSON", p->c_str(), 1);
  }
  if (auto p = args.opt("layer-path")) {
    if (!std::filesystem::is_directory(*p)) throw core::InputError("--layer-path " + *p + ": not a directory");
    setenv("XR_API_LAYER_PATH", p->c_str(), 1);
  }
  nlohmann::json j;
  Loader l;
  l.lib = dlopen("libopenxr_loader.so.1", RTLD_NOW | RTLD_LOCAL);
  if (!l.lib) {
    std::cerr << "fovea xr-info: cannot open the OpenXR loader (libopenxr_loader.so.1): " << dlerror() << "\n";
    return 1;
  }
  l.gipa = reinterpret_cast<PFN_xrGetInstanceProcAddr>(dlsym(l.lib, "xrGetInstanceProcAddr"));
  l.enumerate_layers = reinterpret_cast<PFN_xrEnumerateApiLayerProperties>(dlsym(l.lib, "xrEnumerateApiLayerProperties"));
  l.create = reinterpret_cast<PFN_xrCreateInstance>(dlsym(l.lib, "xrCreateInstance"));
  if (!l.gipa || !l.enumerate_layers || !l.create) {
    std::cerr << "fovea xr-info: the OpenXR loader lacks its core entry points\n";
    return 1;
  }
  j["loader"] = "libopenxr_loader.so.1";
  j["runtime_manifest"] = active_runtime_manifest();
  j["layers"] = nlohmann::json::array();
  bool found = false;
  uint32_t n = 0;
  if (XR_SUCCEEDED(l.enumerate_layers(0, &n, nullptr)) && n) {
    std::vector<XrApiLayerProperties> props(n, {XR_TYPE_API_LAYER_PROPERTIES});
    if (XR_SUCCEEDED(l.enumerate_layers(n, &n, props.data())))
      for (uint32_t i = 0; i < n; ++i) {
        j["layers"].push_back({{"name", props[i].layerName},
                               {"spec_version", std::to_string(XR_VERSION_MAJOR(props[i].specVersion)) + "." +
                                                    std::to_string(XR_VERSION_MINOR(props[i].specVersion)) + "." +
                                                    std::to_string(XR_VERSION_PATCH(props[i].specVersion))},
                               {"layer_version", props[i].layerVersion},
                               {"description", props[i].description}});
        found |= std::string(props[i].layerName) == kFoveaLayer;
      }
  }
  j["runtime"] = try_instance(l, nullptr);
  nlohmann::json f = {{"name", kFoveaLayer}, {"found", found}, {"loads", false}};
  if (found) {
    const auto r = try_instance(l, kFoveaLayer);
    f["loads"] = r["loads"];
    f["result"] = r["result"];
  }
  j["fovea_layer"] = f;
  if (args.has("json"))
    std::cout << j.dump(2) << "\n";
  else
    print_text(j);
  // Scripts (and CI) check the exit status: no runtime is a failure, whatever the format.
  if (!j["runtime"]["loads"].get<bool>()) {
    std::cerr << "fovea xr-info: no OpenXR runtime loads (" << j["runtime"]["result"].get<std::string>() << ")\n";
    return 1;
  }
  return 0;
}

}  // namespace

FOVEA_COMMAND(xr_info_command, "xr-info", "OpenXR runtime and API layers the loader sees (Fovea's included)", run);

}  // namespace fovea::tools
