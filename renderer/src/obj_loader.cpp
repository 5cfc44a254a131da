// Wavefront OBJ/MTL through tinyobjloader (the Debian library); indices and material
// ids it returns are range-checked here, textures decoded with stb_image.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include <stb/stb_image.h>
#include <tiny_obj_loader.h>

#include "fovea/core/error.hpp"
#include "fovea/renderer/scene_io.hpp"

namespace fovea::renderer {

namespace {

// Decodes an image file into an RGBA8 texture; empty optional-like result on failure.
bool load_texture_file(const std::string& path, int max_size, Texture& t) {
  int w = 0, h = 0, n = 0;
  if (!stbi_info(path.c_str(), &w, &h, &n) || w < 1 || h < 1 || w > max_size || h > max_size) return false;
  unsigned char* px = stbi_load(path.c_str(), &w, &h, &n, 4);
  if (!px) return false;
  t.width = w;
  t.height = h;
  t.rgba.assign(px, px + std::size_t(w) * h * 4);
  stbi_image_free(px);
  return true;
}

// Blinn-Phong exponent -> GGX: alpha = sqrt(2 / (Ns + 2)) (Walter et al. 2007, §5.2),
// roughness = sqrt(alpha) in the glTF perceptual parameterisation.
float ns_to_roughness(float ns) {
  if (!std::isfinite(ns) || ns < 0) ns = 0;
  return std::sqrt(std::sqrt(2.0f / (ns + 2.0f)));
}

}  // namespace

Scene load_obj(const std::string& path, const SceneLimits& limits) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw core::InputError(path + ": not a readable file");
  tinyobj::ObjReaderConfig cfg;
  cfg.triangulate = true;
  cfg.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, cfg)) {
    std::string e = reader.Error();
    if (const auto nl = e.find('\n'); nl != std::string::npos) e.resize(nl);
    throw core::InputError(path + ": not a valid OBJ file: " + (e.empty() ? "parse error" : e));
  }
  Scene s;
  s.name = std::filesystem::path(path).stem().string();
  const std::string dir = std::filesystem::path(path).parent_path().string();
  if (!reader.Warning().empty()) {
    std::string w = reader.Warning();
    if (const auto nl = w.find('\n'); nl != std::string::npos) w.resize(nl);
    s.warnings.push_back(path + ": " + w);
  }

  Material def;
  def.name = "obj-default";
  const std::uint32_t def_id = s.add_material(def);
  std::map<std::string, int> texture_ids;
  std::vector<std::uint32_t> mat_map;
  for (const auto& om : reader.GetMaterials()) {
    Material m;
    m.name = om.name;
    m.base_color = {om.diffuse[0], om.diffuse[1], om.diffuse[2]};
    m.specular = std::max({om.specular[0], om.specular[1], om.specular[2]});
    m.roughness = ns_to_roughness(om.shininess);
    m.emission = {om.emission[0], om.emission[1], om.emission[2]};
    if (!om.diffuse_texname.empty()) {
      auto it = texture_ids.find(om.diffuse_texname);
      if (it == texture_ids.end()) {
        Texture t;
        t.name = om.diffuse_texname;
        const std::string tp = (std::filesystem::path(dir) / om.diffuse_texname).string();
        int id = -1;
        if (load_texture_file(tp, limits.max_texture_size, t)) {
          id = int(s.textures.size());
          s.textures.push_back(std::move(t));
        } else {
          s.warnings.push_back(path + ": texture \"" + om.diffuse_texname + "\" missing or undecodable, ignored");
        }
        it = texture_ids.emplace(om.diffuse_texname, id).first;
      }
      m.base_color_texture = it->second;
    }
    mat_map.push_back(s.add_material(m));
  }

  const auto& a = reader.GetAttrib();
  const std::size_t nv = a.vertices.size() / 3, nn = a.normals.size() / 3, nt = a.texcoords.size() / 2;
  std::size_t bad_index = 0, bad_mat = 0, non_tri = 0;
  for (const auto& shape : reader.GetShapes()) {
    const auto& mesh = shape.mesh;
    std::size_t off = 0;
    for (std::size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      const std::size_t fv = mesh.num_face_vertices[f];
      if (off + fv > mesh.indices.size()) break;
      if (fv != 3) {
        ++non_tri;
        off += fv;
        continue;
      }
      glm::vec3 P[3], N[3];
      glm::vec2 T[3];
      bool ok = true;
      for (int k = 0; k < 3; ++k) {
        const auto& ix = mesh.indices[off + k];
        if (ix.vertex_index < 0 || std::size_t(ix.vertex_index) >= nv) { ok = false; break; }
        const std::size_t v = std::size_t(ix.vertex_index);
        P[k] = {a.vertices[3 * v], a.vertices[3 * v + 1], a.vertices[3 * v + 2]};
        N[k] = glm::vec3(0);
        if (ix.normal_index >= 0 && std::size_t(ix.normal_index) < nn) {
          const std::size_t n = std::size_t(ix.normal_index);
          N[k] = {a.normals[3 * n], a.normals[3 * n + 1], a.normals[3 * n + 2]};
        }
        T[k] = glm::vec2(0);
        if (ix.texcoord_index >= 0 && std::size_t(ix.texcoord_index) < nt) {
          const std::size_t t = std::size_t(ix.texcoord_index);
          // OBJ texture space has v up; our textures store the top row first.
          T[k] = {a.texcoords[2 * t], 1.0f - a.texcoords[2 * t + 1]};
        }
      }
      off += fv;
      if (!ok) { ++bad_index; continue; }
      std::uint32_t mat = def_id;
      const int mid = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
      if (mid >= 0 && std::size_t(mid) < mat_map.size()) mat = mat_map[std::size_t(mid)];
      else if (mid >= 0) ++bad_mat;
      s.add_triangle(P[0], P[1], P[2], mat, N[0], N[1], N[2], T[0], T[1], T[2]);
      if (s.triangle_count() > limits.max_triangles)
        throw core::InputError(path + ": more than " + std::to_string(limits.max_triangles) + " triangles");
    }
  }
  if (bad_index) s.warnings.push_back(path + ": " + std::to_string(bad_index) + " faces with out-of-range vertex indices dropped");
  if (bad_mat) s.warnings.push_back(path + ": " + std::to_string(bad_mat) + " faces with an invalid material id use the default material");
  if (non_tri) s.warnings.push_back(path + ": " + std::to_string(non_tri) + " non-triangle faces skipped");
  sanitize(s, path, limits);
  return s;
}

}  // namespace fovea::renderer
