// Wavefront OBJ/MTL through tinyobjloader (the Debian library); indices and material
// ids it returns are range-checked here, textures decoded with stb_image. The OBJ file and
// the material libraries it names are read here with a size bound (tinyobjloader reads
// an endless file until memory runs out) and their numbers screened before parsing.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include <tiny_obj_loader.h>

#include "fovea/core/error.hpp"
#include "fovea/core/input_limits.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "texture_decode.hpp"

namespace fovea::renderer {

namespace {

// Decodes an image file into an RGBA8 texture, reading it within the byte budget; false
// if missing or undecodable, throws beyond the budgets.
bool load_texture_file(const std::string& path, const SceneLimits& limits, const std::string& origin,
                       std::size_t& budget, std::size_t& decoded, Texture& t) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  const std::string bytes = core::read_file_bounded(path, budget);
  budget -= bytes.size();
  std::string why;
  return detail::decode_texture({reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()}, limits, origin,
                                decoded, t, why);
}

// tinyobjloader accumulates a number's exponent in an int without a bound ("1e9999999999"
// overflows it: undefined behaviour). Numeric tokens whose exponent has more than four
// significant digits are refused first, naming the line; no float needs more than three.
void check_exponents(std::string_view text, const std::string& origin) {
  std::size_t line = 1, i = 0;
  const auto digit = [&](std::size_t k) { return k < text.size() && text[k] >= '0' && text[k] <= '9'; };
  while (i < text.size()) {
    const char ch = text[i];
    if (ch == '\n') ++line;
    // A token starts after whitespace or '/' (face indices) with a sign, digit or point.
    const bool starts = (i == 0 || std::isspace(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '/') &&
                        (digit(i) || ch == '+' || ch == '-' || ch == '.');
    if (!starts) {
      ++i;
      continue;
    }
    std::size_t k = i + (ch == '+' || ch == '-');
    while (digit(k) || (k < text.size() && text[k] == '.')) ++k;
    if (k < text.size() && (text[k] == 'e' || text[k] == 'E')) {
      ++k;
      if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
      while (k < text.size() && text[k] == '0') ++k;
      std::size_t significant = 0;
      while (digit(k)) ++k, ++significant;
      if (significant > 4)
        throw core::InputError(origin + ":" + std::to_string(line) + ": number with an exponent out of range");
    }
    i = std::max(k, i + 1);
  }
}

// tinyobjloader reads "nan" and "inf" as 0 without a word, so a vertex of NaNs became the
// origin and the scene's NaN check never saw it. Numeric statements holding such a token
// are refused, naming the line; names (o, g, usemtl, ...) may spell anything.
void check_non_finite(std::string_view text, const std::string& origin) {
  static const std::set<std::string, std::less<>> numeric = {"v",  "vn", "vt", "vp", "Ka", "Kd", "Ks", "Ke",
                                                             "Tf", "Ns", "Ni", "d",  "Tr", "Pr", "Pm"};
  std::size_t line = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view l(text.data() + at, end - at);
    at = end + 1;
    ++line;
    std::size_t i = 0;
    const auto word = [&] {
      while (i < l.size() && std::isspace(static_cast<unsigned char>(l[i]))) ++i;
      const std::size_t b = i;
      while (i < l.size() && !std::isspace(static_cast<unsigned char>(l[i]))) ++i;
      return l.substr(b, i - b);
    };
    if (!numeric.contains(word())) continue;
    for (std::string_view w = word(); !w.empty(); w = word()) {
      std::string_view v = w;
      if (v[0] == '+' || v[0] == '-') v.remove_prefix(1);
      std::string lower(v.substr(0, 3));
      for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (lower == "nan" || lower == "inf")
        throw core::InputError(origin + ":" + std::to_string(line) + ": non-finite number \"" + std::string(w) + "\"");
    }
  }
}

// The material libraries named by `mtllib` lines, concatenated (tinyobjloader takes one
// material stream for all of them), each read with what is left of the byte budget.
std::string read_material_libraries(const std::string& obj, const std::string& dir, std::size_t& budget,
                                    std::vector<std::string>& warnings, const std::string& origin) {
  std::string out;
  std::set<std::string> seen;
  for (std::size_t at = 0; at < obj.size();) {
    const std::size_t end = std::min(obj.find('\n', at), obj.size());
    const std::string_view line(obj.data() + at, end - at);
    at = end + 1;
    if (line.find("mtllib") == std::string_view::npos) continue;  // no copy of the other lines
    std::istringstream words{std::string(line)};
    std::string keyword, name;
    if (!(words >> keyword) || keyword != "mtllib") continue;
    while (words >> name) {
      if (!seen.insert(name).second) continue;
      const std::string path = (std::filesystem::path(dir) / name).string();
      std::error_code ec;
      if (!std::filesystem::is_regular_file(path, ec)) {
        warnings.push_back(origin + ": material library \"" + name + "\" missing, ignored");
        continue;
      }
      try {
        const std::string text = core::read_file_bounded(path, budget);
        budget -= text.size();
        check_exponents(text, path);
        check_non_finite(text, path);
        out += text;
      } catch (const core::InputError& e) {
        throw core::InputError(origin + ": mtllib " + e.what());
      }
      out += '\n';
    }
  }
  return out;
}

// Blinn-Phong exponent -> GGX: alpha = sqrt(2 / (Ns + 2)) (Walter et al. 2007, §5.2),
// roughness = sqrt(alpha) in the glTF perceptual parameterisation.
float ns_to_roughness(float ns) {
  if (!std::isfinite(ns) || ns < 0) ns = 0;
  return std::sqrt(std::sqrt(2.0f / (ns + 2.0f)));
}

}  // namespace

Scene load_obj(const std::string& path, const SceneLimits& limits) {
  const std::string obj = core::read_file_bounded(path, limits.max_file_bytes);
  check_exponents(obj, path);
  check_non_finite(obj, path);
  Scene s;
  const std::string dir = std::filesystem::path(path).parent_path().string();
  std::size_t budget = limits.max_file_bytes - obj.size();
  const std::string mtl = read_material_libraries(obj, dir, budget, s.warnings, path);
  tinyobj::ObjReaderConfig cfg;
  cfg.triangulate = true;
  cfg.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(obj, mtl, cfg)) {
    std::string e = reader.Error();
    if (const auto nl = e.find('\n'); nl != std::string::npos) e.resize(nl);
    throw core::InputError(path + ": not a valid OBJ file: " + (e.empty() ? "parse error" : e));
  }
  s.name = std::filesystem::path(path).stem().string();
  if (!reader.Warning().empty()) {
    std::string w = reader.Warning();
    if (const auto nl = w.find('\n'); nl != std::string::npos) w.resize(nl);
    s.warnings.push_back(path + ": " + w);
  }

  Material def;
  def.name = "obj-default";
  const std::uint32_t def_id = s.add_material(def);
  std::map<std::string, int> texture_ids;
  std::size_t decoded = 0;
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
        if (load_texture_file(tp, limits, path, budget, decoded, t)) {
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
