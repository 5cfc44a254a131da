#pragma once
// A renderable scene: unindexed triangles with per-vertex shading normals and texture
// coordinates, one material per triangle, base-colour textures, an optional constant
// environment and a default eye pose. Loaders and procedural builders produce it;
// `sanitize` makes any of them safe to build a BVH from and to upload.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "fovea/core/view.hpp"

namespace fovea::renderer {

// RGBA8, sRGB-encoded colour, row-major, top row first.
struct Texture {
  std::string name;
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
};

// GGX specular (Smith masking, multiple-scattering compensated) over an energy-compensated
// Lambert base, glTF metallic-roughness semantics: diffuse colour = base·(1−metallic);
// specular F0 = mix(specular, base, metallic). docs/renderer.md has the model.
struct Material {
  std::string name;
  glm::vec3 base_color{0.8f};
  int base_color_texture = -1;  // index into Scene::textures, multiplies base_color
  float metallic = 0.0f;
  float roughness = 1.0f;        // perceptual (GGX alpha = roughness²)
  float specular = 0.04f;        // dielectric F0; 0 makes a pure Lambert surface
  glm::vec3 emission{0.0f};      // radiance emitted (linear)
  // glTF `doubleSided`: back faces are shaded and emit with the normal reversed. Single-sided
  // back faces neither reflect nor emit (black, still opaque). Built-in scenes and OBJ files
  // (which cannot say) are double-sided except the built-in emitters.
  bool double_sided = true;
};

struct Scene {
  std::string name;
  // Three entries per triangle in each vertex array; `material` has one per triangle.
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> material;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  glm::vec3 environment{0.0f};  // constant radiance of rays that leave the scene
  core::Pose camera;            // default eye pose (glTF camera or built-in)
  std::vector<std::string> warnings;

  std::size_t triangle_count() const { return material.size(); }
  // Appends a triangle; a zero normal asks for the geometric normal.
  void add_triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, std::uint32_t mat,
                    glm::vec3 na = {}, glm::vec3 nb = {}, glm::vec3 nc = {},
                    glm::vec2 ta = {}, glm::vec2 tb = {}, glm::vec2 tc = {});
  // Two triangles a-b-c, a-c-d.
  void add_quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t mat);
  std::uint32_t add_material(const Material& m);
};

// Limits past which a scene is refused (InputError) rather than loaded.
struct SceneLimits {
  std::size_t max_triangles = 4'000'000;
  double max_coordinate = 1e8;  // |x| beyond this (after transforms) drops the triangle
  int max_texture_size = 16384;
  // Node instantiations while walking a glTF node graph: a DAG listing children twice
  // doubles the walk per level, whether or not it reaches any triangles.
  std::size_t max_node_instances = 1'000'000;
  std::size_t max_texture_bytes = std::size_t(512) << 20;  // all decoded textures (RGBA8)
  std::size_t max_file_bytes = std::size_t(1) << 30;       // a scene file plus the files it names
};

// Makes a scene safe: drops triangles with non-finite or out-of-range positions or zero
// area, repairs non-finite/zero normals and non-finite UVs, clamps material parameters
// to their valid ranges, drops invalid texture references. Every change is recorded in
// `warnings` (one line per kind, with counts). Throws core::InputError when nothing
// renderable remains or a limit is exceeded; `origin` names the input in messages.
void sanitize(Scene& scene, const std::string& origin, const SceneLimits& limits = {});

// Axis-aligned bounds of all triangles (min, max).
std::pair<glm::vec3, glm::vec3> scene_bounds(const Scene& scene);

// Emitted power proxy of a triangle: area × luminance(emission) (W up to a constant).
float triangle_power(const Scene& scene, std::size_t tri);

// How much of the light a path keeps per bounce in this scene. A material's albedo is the
// largest channel of F0 + (1 − F0)·ρd, the normal-incidence reflectance of the layered BSDF
// (ρd = base·(1 − metallic), F0 = mix(specular, base, metallic); textures multiply the base
// with their mean colour for `mean` and their brightest texel for `max`). Emissive
// surfaces count like the others. mean: weighted by triangle area; max: over the triangles.
struct AlbedoStats {
  float mean = 0.0f, max = 0.0f;
};
AlbedoStats albedo_stats(const Scene& scene);

}  // namespace fovea::renderer
