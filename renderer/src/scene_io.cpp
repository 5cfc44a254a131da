#include "fovea/renderer/scene_io.hpp"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <span>

#include "fovea/core/error.hpp"
#include "fovea/renderer/procedural.hpp"

namespace fovea::renderer {

namespace embedded_scenes {
std::span<const std::uint8_t> find(std::string_view name);
}

namespace {
constexpr const char* kDefaultScene = "default.gltf";
}

std::vector<std::string> builtin_scene_names() {
  return {"cornell", "furnace", "glossy-spheres", "stereo-occluders", "default"};
}

Scene load_scene(std::string_view name_or_path, const SceneLimits& limits) {
  const std::string name(name_or_path);
  Scene s;
  if (name == "cornell") s = make_cornell();
  else if (name == "furnace") s = make_furnace();
  else if (name == "glossy-spheres") s = make_glossy_spheres();
  else if (name == "stereo-occluders") s = make_stereo_occluders();
  else if (name == "default") {
    const auto bytes = embedded_scenes::find(kDefaultScene);
    if (bytes.empty()) throw core::InputError("scene \"default\": not embedded in this build");
    return load_gltf_text(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                          "default", "", limits);
  } else {
    std::string ext = std::filesystem::path(name).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".gltf" || ext == ".glb") return load_gltf(name, limits);
    if (ext == ".obj") return load_obj(name, limits);
    std::string names;
    for (const auto& n : builtin_scene_names()) names += (names.empty() ? "" : ", ") + n;
    throw core::InputError("scene \"" + name + "\": neither a built-in scene (" + names +
                           ") nor a .gltf/.glb/.obj file");
  }
  sanitize(s, name, limits);
  return s;
}

}  // namespace fovea::renderer
