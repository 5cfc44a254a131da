#pragma once
// Scene loading by name: a built-in procedural scene, the embedded default glTF scene,
// or a path to a glTF 2.0 (.gltf/.glb) or OBJ/MTL file.
#include <string>
#include <string_view>
#include <vector>

#include "fovea/renderer/scene.hpp"

namespace fovea::renderer {

// "cornell", "furnace", "glossy-spheres", "stereo-occluders", "default" or a file path.
// Bad files are loaded with the offending parts dropped (listed in Scene::warnings) or
// refused with core::InputError naming the file and the problem; never a crash.
Scene load_scene(std::string_view name_or_path, const SceneLimits& limits = {});
std::vector<std::string> builtin_scene_names();

// glTF 2.0: meshes (triangles), node transforms, metallic-roughness materials with
// base-colour textures, emission (with KHR_materials_emissive_strength), cameras (the
// first camera node found gives Scene::camera).
Scene load_gltf(const std::string& path, const SceneLimits& limits = {});
// The same from memory; `base_dir` resolves external URIs ("" allows data URIs only).
Scene load_gltf_text(std::string_view text, const std::string& origin, const std::string& base_dir,
                     const SceneLimits& limits = {});
// OBJ/MTL: Kd, Ks/Ns (→ F0 and roughness), Ke, map_Kd.
Scene load_obj(const std::string& path, const SceneLimits& limits = {});

}  // namespace fovea::renderer
