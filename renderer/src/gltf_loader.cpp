// glTF 2.0 through tinygltf (the Debian library). tinygltf parses the JSON; images are
// decoded here (stb_image), only those a material uses. Before tinygltf sees the text its
// JSON nesting is bounded (tinygltf converts `extras` recursively), files it reads go
// through a size budget, and everything it hands back is treated as untrusted: every
// index, offset, stride and count is checked here before use.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>
#include <span>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <tiny_gltf.h>

#include "fovea/core/error.hpp"
#include "fovea/core/input_limits.hpp"
#include "fovea/core/json.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "texture_decode.hpp"

namespace fovea::renderer {

namespace {

using tinygltf::Model;

struct Ctx {
  const Model& m;
  Scene& s;
  std::string origin;
  const SceneLimits& limits;
  std::vector<std::uint32_t> material_map;  // glTF material index -> scene material
  std::uint32_t default_material = 0;
  bool have_camera = false;
  std::size_t triangles_seen = 0;  // triangles instantiated so far (DAGs can explode)
  std::size_t node_instances = 0;  // nodes visited so far, for the same reason

  void warn(const std::string& w) {
    if (std::find(s.warnings.begin(), s.warnings.end(), origin + ": " + w) == s.warnings.end())
      s.warnings.push_back(origin + ": " + w);
  }
};

int component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;
  }
}

int component_size(int ct) {
  switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

// One component as a double; normalised integers map to [0,1] / [-1,1] (glTF §3.11).
double read_component(const unsigned char* p, int ct, bool normalized) {
  switch (ct) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); return f; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v; std::memcpy(&v, p, 2); return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v; std::memcpy(&v, p, 2); return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? *p / 255.0 : *p;
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const auto v = static_cast<std::int8_t>(*p); return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    default: return 0;
  }
}

// Reads `count` elements of `nc` components of type `ct` from buffer view `view` at
// `offset`: false (with `why`, naming `what`) for anything outside the view or its buffer.
bool read_view(const Model& m, int view, std::size_t offset, std::size_t count, int nc, int ct, bool normalized,
               const std::string& what, std::vector<double>& out, std::string& why) {
  if (view < 0 || std::size_t(view) >= m.bufferViews.size()) {
    why = what + " references a missing bufferView";
    return false;
  }
  const auto& bv = m.bufferViews[std::size_t(view)];
  if (bv.buffer < 0 || std::size_t(bv.buffer) >= m.buffers.size()) {
    why = "bufferView " + std::to_string(view) + " references a missing buffer";
    return false;
  }
  const auto& buf = m.buffers[std::size_t(bv.buffer)].data;
  const std::size_t cs = std::size_t(component_size(ct)), elem = std::size_t(nc) * cs;
  const std::size_t stride = bv.byteStride ? bv.byteStride : elem;
  // All arithmetic checked against the buffer size without overflow.
  const std::size_t view_off = bv.byteOffset, view_len = bv.byteLength;
  if (stride < elem || stride > 252 || view_off > buf.size() || view_len > buf.size() - view_off ||
      offset > view_len || count > (std::size_t(1) << 31) ||
      (count > 0 && ((count - 1) > (view_len - offset) / stride || (count - 1) * stride + elem > view_len - offset))) {
    why = what + " lies outside its buffer";
    return false;
  }
  out.resize(count * std::size_t(nc));
  const unsigned char* base = buf.data() + view_off + offset;
  for (std::size_t i = 0; i < count; ++i)
    for (int c = 0; c < nc; ++c)
      out[i * nc + c] = read_component(base + i * stride + std::size_t(c) * cs, ct, normalized);
  return true;
}

// Reads accessor `index` as `comps` doubles per element, with its sparse substitutions
// (glTF 2.0 §3.6.2.3: the dense values, or zeros without a bufferView, then `sparse.count`
// values at their indices). Returns false (with `why`) for anything out of range: indices,
// offsets, strides, counts, types.
bool read_accessor(const Model& m, int index, int comps, std::vector<double>& out, std::string& why) {
  if (index < 0 || std::size_t(index) >= m.accessors.size()) {
    why = "accessor index " + std::to_string(index) + " out of range";
    return false;
  }
  const auto& a = m.accessors[std::size_t(index)];
  const std::string what = "accessor " + std::to_string(index);
  const int nc = component_count(a.type);
  if (nc != comps || component_size(a.componentType) == 0) { why = what + " has an unexpected type"; return false; }
  const std::size_t count = a.count;
  if (!a.sparse.isSparse || a.bufferView >= 0) {
    if (!read_view(m, a.bufferView, a.byteOffset, count, nc, a.componentType, a.normalized, what, out, why))
      return false;
  } else {
    if (count > (std::size_t(1) << 31)) { why = what + " lies outside its buffer"; return false; }
    out.assign(count * std::size_t(nc), 0.0);
  }
  if (!a.sparse.isSparse) return true;
  const auto& sp = a.sparse;
  const int it = sp.indices.componentType;
  if (sp.count < 1 || std::size_t(sp.count) > count ||
      !(it == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || it == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
        it == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)) {
    why = what + " has a sparse count or index type out of range";
    return false;
  }
  std::vector<double> at, values;
  if (!read_view(m, sp.indices.bufferView, std::size_t(std::max(sp.indices.byteOffset, 0)), std::size_t(sp.count), 1,
                 it, false, what + "'s sparse indices", at, why) ||
      !read_view(m, sp.values.bufferView, std::size_t(std::max(sp.values.byteOffset, 0)), std::size_t(sp.count), nc,
                 a.componentType, a.normalized, what + "'s sparse values", values, why))
    return false;
  for (std::size_t k = 0; k < at.size(); ++k) {
    if (!(at[k] < double(count))) { why = what + " has a sparse index out of range"; return false; }
    for (int c = 0; c < nc; ++c) out[std::size_t(at[k]) * nc + c] = values[k * nc + c];
  }
  return true;
}

int find_attribute(const tinygltf::Primitive& p, const char* name) {
  const auto it = p.attributes.find(name);
  return it == p.attributes.end() ? -1 : it->second;
}

// Images as tinygltf found them, still encoded, by image index (empty: the image lives in
// a buffer view, or its URI could not be read).
struct EncodedImages {
  std::vector<std::vector<unsigned char>> bytes;
};

// tinygltf's image callback: keeps the encoded bytes for load_textures. For images in a
// buffer view tinygltf passes a pointer it has not range-checked against the buffer (a
// view past the end crashed the decoder); those are read later through a checked view.
bool keep_encoded(tinygltf::Image* img, int index, std::string*, std::string*, int, int,
                  const unsigned char* bytes, int size, void* user) {
  if (img->bufferView >= 0 || index < 0 || size <= 0) return true;
  auto& store = static_cast<EncodedImages*>(user)->bytes;
  if (store.size() <= std::size_t(index)) store.resize(std::size_t(index) + 1);
  store[std::size_t(index)].assign(bytes, bytes + size);
  return true;
}

// The encoded bytes of image `src`; empty with `why` set if there are none.
std::span<const unsigned char> encoded_image(const Model& m, const EncodedImages& enc, int src, std::string& why) {
  if (src < 0 || std::size_t(src) >= m.images.size()) {
    why = "texture without a valid image";
    return {};
  }
  const auto& img = m.images[std::size_t(src)];
  if (img.bufferView >= 0) {
    const auto bvi = std::size_t(img.bufferView);
    const auto* bv = bvi < m.bufferViews.size() ? &m.bufferViews[bvi] : nullptr;
    const auto* buf = bv && bv->buffer >= 0 && std::size_t(bv->buffer) < m.buffers.size()
                          ? &m.buffers[std::size_t(bv->buffer)].data : nullptr;
    if (!buf || bv->byteOffset > buf->size() || bv->byteLength > buf->size() - bv->byteOffset) {
      why = "image " + std::to_string(src) + ": bufferView " + std::to_string(img.bufferView) + " lies outside its buffer";
      return {};
    }
    return {buf->data() + bv->byteOffset, bv->byteLength};
  }
  if (std::size_t(src) < enc.bytes.size() && !enc.bytes[std::size_t(src)].empty()) return enc.bytes[std::size_t(src)];
  why = "image \"" + img.uri.substr(0, 64) + "\" missing";
  return {};
}

// One scene texture per glTF texture (material indices stay valid); only the textures a
// material uses are decoded, the others stay 1x1 white.
void load_textures(Ctx& c, const EncodedImages& enc) {
  std::vector<bool> used(c.m.textures.size(), false);
  for (const auto& gm : c.m.materials) {
    const int ti = gm.pbrMetallicRoughness.baseColorTexture.index;
    if (ti >= 0 && std::size_t(ti) < used.size()) used[std::size_t(ti)] = true;
  }
  std::size_t decoded = 0;
  for (std::size_t i = 0; i < c.m.textures.size(); ++i) {
    Texture t;
    t.name = c.m.textures[i].name;
    if (used[i]) {
      std::string why;
      const auto bytes = encoded_image(c.m, enc, c.m.textures[i].source, why);
      if (why.empty() && !detail::decode_texture(bytes, c.limits, c.origin, decoded, t, why))
        why = "image \"" + c.m.images[std::size_t(c.m.textures[i].source)].uri.substr(0, 64) + "\" " + why;
      if (t.width == 0) c.warn(why + ", replaced by white");
    }
    if (t.width == 0) {
      t.width = t.height = 1;
      t.rgba = {255, 255, 255, 255};
    }
    c.s.textures.push_back(std::move(t));
  }
}

void load_materials(Ctx& c) {
  Material def;
  def.name = "gltf-default";  // glTF §3.9.6: the default material
  def.base_color = glm::vec3(1.0f);
  def.metallic = 1.0f;
  def.roughness = 1.0f;
  def.double_sided = false;
  c.default_material = c.s.add_material(def);
  for (const auto& gm : c.m.materials) {
    Material m;
    m.name = gm.name;
    const auto& pbr = gm.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() >= 3)
      m.base_color = glm::vec3(float(pbr.baseColorFactor[0]), float(pbr.baseColorFactor[1]), float(pbr.baseColorFactor[2]));
    m.metallic = float(pbr.metallicFactor);
    m.roughness = float(pbr.roughnessFactor);
    m.double_sided = gm.doubleSided;  // glTF §3.9.5, default false
    const int ti = pbr.baseColorTexture.index;
    if (ti >= 0 && std::size_t(ti) < c.s.textures.size()) m.base_color_texture = ti;
    else if (ti >= 0) c.warn("material \"" + gm.name + "\" references a missing texture, ignored");
    if (gm.emissiveFactor.size() >= 3)
      m.emission = glm::vec3(float(gm.emissiveFactor[0]), float(gm.emissiveFactor[1]), float(gm.emissiveFactor[2]));
    const auto ext = gm.extensions.find("KHR_materials_emissive_strength");
    if (ext != gm.extensions.end() && ext->second.IsObject() && ext->second.Has("emissiveStrength") &&
        ext->second.Get("emissiveStrength").IsNumber())
      m.emission *= float(ext->second.Get("emissiveStrength").GetNumberAsDouble());
    c.material_map.push_back(c.s.add_material(m));
  }
}

bool finite_matrix(const glm::dmat4& t) {
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (!std::isfinite(t[i][j])) return false;
  return true;
}

glm::dmat4 local_transform(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) return glm::make_mat4(n.matrix.data());
  glm::dmat4 t(1.0);
  if (n.translation.size() == 3) t = glm::translate(t, glm::dvec3(n.translation[0], n.translation[1], n.translation[2]));
  if (n.rotation.size() == 4) {
    glm::dquat q(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);
    const double len = glm::length(q);
    if (len > 0 && std::isfinite(len)) t = t * glm::mat4_cast(q / len);
  }
  if (n.scale.size() == 3) t = glm::scale(t, glm::dvec3(n.scale[0], n.scale[1], n.scale[2]));
  return t;
}

// A triangle strip's or fan's vertex list as a triangle list, keeping each triangle's winding
// (glTF 2.0 §3.7.2.1: strip p_i = {v_i, v_{i+1+i%2}, v_{i+2-i%2}}, fan p_i = {v_{i+1}, v_{i+2}, v_0}).
std::vector<double> triangle_list(int mode, std::vector<double> v) {
  if (mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) return v;
  std::vector<double> t;
  for (std::size_t i = 0; i + 2 < v.size(); ++i) {
    if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) t.insert(t.end(), {v[i], v[i + 1 + i % 2], v[i + 2 - i % 2]});
    else t.insert(t.end(), {v[i + 1], v[i + 2], v[0]});
  }
  return t;
}

void add_primitive(Ctx& c, const tinygltf::Primitive& p, const glm::dmat4& world, const std::string& mesh_name) {
  const std::string where = "mesh \"" + mesh_name + "\"";
  const bool list = p.mode == TINYGLTF_MODE_TRIANGLES || p.mode == -1;
  if (!list && p.mode != TINYGLTF_MODE_TRIANGLE_STRIP && p.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    c.warn(where + ": point or line primitive skipped");
    return;
  }
  std::string why;
  std::vector<double> pos, nrm, uv, idx;
  if (!read_accessor(c.m, find_attribute(p, "POSITION"), 3, pos, why)) {
    c.warn(where + ": primitive skipped, POSITION: " + why);
    return;
  }
  const std::size_t nv = pos.size() / 3;
  const int ni = find_attribute(p, "NORMAL"), nt = find_attribute(p, "TEXCOORD_0");
  if (ni >= 0 && (!read_accessor(c.m, ni, 3, nrm, why) || nrm.size() != pos.size())) {
    c.warn(where + ": normals ignored (" + (why.empty() ? "count mismatch" : why) + ")");
    nrm.clear();
  }
  why.clear();
  if (nt >= 0 && (!read_accessor(c.m, nt, 2, uv, why) || uv.size() != 2 * nv)) {
    c.warn(where + ": texture coordinates ignored (" + (why.empty() ? "count mismatch" : why) + ")");
    uv.clear();
  }
  if (p.indices >= 0) {
    if (!read_accessor(c.m, p.indices, 1, idx, why)) {
      c.warn(where + ": primitive skipped, indices: " + why);
      return;
    }
  } else {
    idx.resize(nv);
    for (std::size_t i = 0; i < nv; ++i) idx[i] = double(i);
  }
  if (list && idx.size() % 3) c.warn(where + ": index count not a multiple of 3, remainder ignored");
  idx = triangle_list(p.mode, std::move(idx));
  std::uint32_t mat = c.default_material;
  if (p.material >= 0 && std::size_t(p.material) < c.material_map.size()) mat = c.material_map[std::size_t(p.material)];
  else if (p.material >= 0) c.warn(where + ": invalid material index, default material used");
  const std::size_t ntri = idx.size() / 3;
  c.triangles_seen += ntri;
  if (c.triangles_seen > c.limits.max_triangles)
    throw core::InputError(c.origin + ": more than " + std::to_string(c.limits.max_triangles) +
                           " triangles after instancing the node graph");
  const glm::dmat3 nmat = glm::transpose(glm::inverse(glm::dmat3(world)));
  // Mirroring transforms reverse the winding; swapping two vertices keeps front faces.
  const bool flip = glm::determinant(glm::dmat3(world)) < 0;
  std::size_t bad = 0;
  for (std::size_t t = 0; t < ntri; ++t) {
    glm::vec3 P[3], N[3];
    glm::vec2 T[3];
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      const double iv = idx[3 * t + k];
      if (!(iv >= 0 && iv < double(nv))) { ok = false; break; }
      const std::size_t v = std::size_t(iv);
      P[k] = glm::vec3(world * glm::dvec4(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], 1.0));
      N[k] = nrm.empty() ? glm::vec3(0) : glm::vec3(nmat * glm::dvec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]));
      T[k] = uv.empty() ? glm::vec2(0) : glm::vec2(float(uv[2 * v]), float(uv[2 * v + 1]));
    }
    if (!ok) { ++bad; continue; }
    if (flip) {
      std::swap(P[1], P[2]);
      std::swap(N[1], N[2]);
      std::swap(T[1], T[2]);
    }
    c.s.add_triangle(P[0], P[1], P[2], mat, N[0], N[1], N[2], T[0], T[1], T[2]);
  }
  if (bad) c.warn(where + ": " + std::to_string(bad) + " triangles with out-of-range indices dropped");
}

void visit(Ctx& c, int node, const glm::dmat4& parent, std::vector<int>& path) {
  if (node < 0 || std::size_t(node) >= c.m.nodes.size()) {
    c.warn("node index " + std::to_string(node) + " out of range, skipped");
    return;
  }
  if (std::find(path.begin(), path.end(), node) != path.end()) {
    c.warn("node graph contains a cycle through node " + std::to_string(node) + ", edge dropped");
    return;
  }
  if (path.size() >= 256) {
    c.warn("node hierarchy deeper than 256 levels, truncated");
    return;
  }
  if (++c.node_instances > c.limits.max_node_instances)
    throw core::InputError(c.origin + ": more than " + std::to_string(c.limits.max_node_instances) +
                           " node instances after instancing the node graph");
  const auto& n = c.m.nodes[std::size_t(node)];
  const glm::dmat4 world = parent * local_transform(n);
  if (!finite_matrix(world)) {
    c.warn("node " + std::to_string(node) + " has a non-finite transform, subtree skipped");
    return;
  }
  if (n.mesh >= 0) {
    if (std::size_t(n.mesh) >= c.m.meshes.size()) {
      c.warn("node " + std::to_string(node) + " references a missing mesh");
    } else {
      const auto& mesh = c.m.meshes[std::size_t(n.mesh)];
      for (const auto& p : mesh.primitives) add_primitive(c, p, world, mesh.name);
    }
  }
  if (n.camera >= 0 && !c.have_camera && std::size_t(n.camera) < c.m.cameras.size()) {
    // glTF cameras look down -Z with +Y up, as OpenXR views do.
    glm::dmat3 r(world);
    for (int i = 0; i < 3; ++i) r[i] = glm::length(r[i]) > 0 ? glm::normalize(r[i]) : r[i];
    const glm::dquat q = glm::quat_cast(r);
    if (std::isfinite(q.w) && std::abs(glm::length(q) - 1.0) < 1e-3) {
      c.s.camera.orientation = glm::normalize(q);
      c.s.camera.position = glm::dvec3(world[3]);
      c.have_camera = true;
    }
  }
  path.push_back(node);
  for (int child : n.children) visit(c, child, world, path);
  path.pop_back();
}

Scene from_model(const Model& m, const EncodedImages& enc, const std::string& origin, const SceneLimits& limits) {
  Scene s;
  s.name = std::filesystem::path(origin).stem().string();
  Ctx c{m, s, origin, limits};
  load_textures(c, enc);
  load_materials(c);
  std::vector<int> roots;
  if (!m.scenes.empty()) {
    const int si = m.defaultScene >= 0 && std::size_t(m.defaultScene) < m.scenes.size() ? m.defaultScene : 0;
    roots = m.scenes[std::size_t(si)].nodes;
  } else {
    // No scene: every node that is nobody's child is a root.
    std::set<int> children;
    for (const auto& n : m.nodes) children.insert(n.children.begin(), n.children.end());
    for (int i = 0; i < int(m.nodes.size()); ++i)
      if (!children.count(i)) roots.push_back(i);
  }
  std::vector<int> path;
  for (int r : roots) visit(c, r, glm::dmat4(1.0), path);
  sanitize(s, origin, limits);
  return s;
}

// tinygltf reports problems as newline-separated text; one line is enough for a message.
std::string first_line(const std::string& s) {
  const auto nl = s.find('\n');
  return s.substr(0, nl);
}

void collect_warnings(Scene& s, const std::string& origin, const std::string& warn) {
  std::size_t start = 0;
  while (start < warn.size()) {
    const auto nl = warn.find('\n', start);
    const std::string line = warn.substr(start, nl == std::string::npos ? std::string::npos : nl - start);
    if (!line.empty()) s.warnings.push_back(origin + ": " + line);
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
}

// Files tinygltf reads (external buffers and images) share the scene's byte budget; text
// loaded from memory without a base directory may use data URIs only.
struct FileBudget {
  std::size_t left;
  bool allow_files;
};

bool file_exists(const std::string& path, void* user) {
  std::error_code ec;
  return static_cast<FileBudget*>(user)->allow_files && std::filesystem::is_regular_file(path, ec);
}

// tinygltf's own expansion runs wordexp() on URIs from the file; paths are taken as written.
std::string path_as_is(const std::string& path, void*) { return path; }

bool read_within_budget(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto& budget = *static_cast<FileBudget*>(user);
  if (!budget.allow_files) {
    if (err) *err += path + ": external files are not allowed here\n";
    return false;
  }
  try {
    const std::string bytes = core::read_file_bounded(path, budget.left);
    budget.left -= bytes.size();
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const core::InputError& e) {
    if (err) *err += std::string(e.what()) + " (the scene's file budget)\n";
    return false;
  }
}

bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing is not supported\n";
  return false;
}

// tinygltf converts `extras` and `extensions` to its Value type recursively.
constexpr std::size_t kMaxJsonDepth = 128;

// The JSON chunk of a GLB container (header: magic, version, length; then chunk length
// and type), or the whole text when it is not one; tinygltf reports malformed containers.
std::string_view glb_json(std::string_view bytes) {
  if (bytes.size() < 20) return {};
  std::uint32_t len = 0;
  std::memcpy(&len, bytes.data() + 12, 4);
  return bytes.substr(20, std::min<std::size_t>(len, bytes.size() - 20));
}

// The glTF extensions this loader reads; an asset that requires another is refused (glTF 2.0
// §3.12). KHR_mesh_quantization allows integer attributes, which read_component reads.
constexpr std::array<std::string_view, 2> kReadExtensions = {"KHR_materials_emissive_strength",
                                                             "KHR_mesh_quantization"};

void check_required(const std::vector<std::string>& required, const std::string& origin) {
  std::string missing;
  for (const std::string& e : required)
    if (std::find(kReadExtensions.begin(), kReadExtensions.end(), e) == kReadExtensions.end())
      missing += (missing.empty() ? "" : ", ") + e;
  if (!missing.empty())
    throw core::InputError(origin + ": requires the glTF extension(s) " + missing + ", which fovea does not read");
}

// The asset's version (glTF 2.0 §3.2's note): with a minVersion, both its major and minor
// version must be readable, here 2.0; otherwise the major version must be 2 (2.x assets are
// backward compatible with 2.0 readers).
void check_version(const tinygltf::Asset& a, const std::string& origin) {
  const auto parse = [](const std::string& v, int& major, int& minor) {
    char tail = 0;
    return std::sscanf(v.c_str(), "%d.%d%c", &major, &minor, &tail) == 2 && major >= 0 && minor >= 0;
  };
  int major = 0, minor = 0;
  if (!a.minVersion.empty()) {
    if (!parse(a.minVersion, major, minor) || major != 2 || minor > 0)
      throw core::InputError(origin + ": needs a reader of glTF " + a.minVersion +
                             " (asset.minVersion); fovea reads glTF 2.0");
  } else if (!parse(a.version, major, minor) || major != 2) {
    throw core::InputError(origin + ": glTF version \"" + a.version + "\" (asset.version); fovea reads glTF 2.x");
  }
}

// The asset's extensionsRequired from its JSON text, when the parser could not load it (a
// compressed mesh's accessors have no data without their extension); empty when unreadable.
std::vector<std::string> required_in_text(std::string_view json) {
  std::vector<std::string> r;
  try {
    const nlohmann::json j = core::parse_json(json);
    if (j.is_object() && j.contains("extensionsRequired") && j["extensionsRequired"].is_array())
      for (const auto& e : j["extensionsRequired"])
        if (e.is_string()) r.push_back(e.get<std::string>());
  } catch (const nlohmann::json::exception&) {
  }
  return r;
}

Scene load(std::string_view bytes, bool binary, const std::string& origin, const std::string& base_dir,
           const SceneLimits& limits) {
  if (bytes.size() > limits.max_file_bytes || bytes.size() > std::numeric_limits<unsigned>::max())
    throw core::InputError(origin + ": larger than " + std::to_string(limits.max_file_bytes) + " bytes, refused");
  core::check_json_nesting(binary ? glb_json(bytes) : bytes, origin, kMaxJsonDepth);
  tinygltf::TinyGLTF loader;
  EncodedImages images;
  FileBudget budget{limits.max_file_bytes - bytes.size(), !base_dir.empty()};
  loader.SetImageLoader(&keep_encoded, &images);
  loader.SetFsCallbacks({&file_exists, &path_as_is, &read_within_budget, &refuse_write, &budget});
  Model m;
  std::string err, warn;
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromMemory(&m, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                              static_cast<unsigned>(bytes.size()), base_dir)
                : loader.LoadASCIIFromString(&m, &err, &warn, bytes.data(), static_cast<unsigned>(bytes.size()), base_dir);
  } catch (const std::exception& e) {  // e.g. JSON type errors thrown from inside the parser
    err = e.what();
  }
  if (!ok) {
    check_required(required_in_text(binary ? glb_json(bytes) : bytes), origin);
    throw core::InputError(origin + ": not a valid glTF 2.0 file: " + first_line(err.empty() ? warn : err));
  }
  check_version(m.asset, origin);
  check_required(m.extensionsRequired, origin);
  Scene s = from_model(m, images, origin, limits);
  collect_warnings(s, origin, warn);
  return s;
}

}  // namespace

Scene load_gltf(const std::string& path, const SceneLimits& limits) {
  const std::string bytes = core::read_file_bounded(path, limits.max_file_bytes);
  const bool binary = path.ends_with(".glb") || path.ends_with(".GLB");
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return load(bytes, binary, path, dir.empty() ? "." : dir, limits);
}

Scene load_gltf_text(std::string_view text, const std::string& origin, const std::string& base_dir,
                     const SceneLimits& limits) {
  return load(text, false, origin, base_dir, limits);
}

}  // namespace fovea::renderer
