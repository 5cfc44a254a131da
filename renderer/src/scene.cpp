#include "fovea/renderer/scene.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"

namespace fovea::renderer {

void Scene::add_triangle(glm::vec3 a, glm::vec3 b, glm::vec3 c, std::uint32_t mat, glm::vec3 na,
                         glm::vec3 nb, glm::vec3 nc, glm::vec2 ta, glm::vec2 tb, glm::vec2 tc) {
  positions.insert(positions.end(), {a, b, c});
  normals.insert(normals.end(), {na, nb, nc});
  uvs.insert(uvs.end(), {ta, tb, tc});
  material.push_back(mat);
}

void Scene::add_quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t mat) {
  add_triangle(a, b, c, mat, {}, {}, {}, {0, 0}, {1, 0}, {1, 1});
  add_triangle(a, c, d, mat, {}, {}, {}, {0, 0}, {1, 1}, {0, 1});
}

std::uint32_t Scene::add_material(const Material& m) {
  materials.push_back(m);
  return static_cast<std::uint32_t>(materials.size() - 1);
}

namespace {

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

float clamp_finite(float v, float lo, float hi, float fallback) {
  return std::isfinite(v) ? std::clamp(v, lo, hi) : fallback;
}

// Collects one warning line per kind of repair, with counts.
class Repairs {
 public:
  void note(const std::string& what, std::size_t n = 1) { counts_[what] += n; }
  void flush(Scene& s, const std::string& origin) {
    for (const auto& [what, n] : counts_)
      s.warnings.push_back(origin + ": " + what + " (" + std::to_string(n) + ")");
  }

 private:
  std::map<std::string, std::size_t> counts_;
};

}  // namespace

void sanitize(Scene& s, const std::string& origin, const SceneLimits& limits) {
  const std::size_t n = s.material.size();
  if (s.positions.size() != 3 * n || s.normals.size() != 3 * n || s.uvs.size() != 3 * n)
    throw core::InputError(origin + ": inconsistent triangle arrays");
  if (n > limits.max_triangles)
    throw core::InputError(origin + ": " + std::to_string(n) + " triangles exceed the limit of " +
                           std::to_string(limits.max_triangles));
  Repairs rep;

  // Materials and textures first, so triangles can be checked against them.
  for (Texture& t : s.textures) {
    if (t.width < 1 || t.height < 1 || t.width > limits.max_texture_size || t.height > limits.max_texture_size ||
        t.rgba.size() != std::size_t(t.width) * t.height * 4) {
      rep.note("unusable texture replaced by white");
      t.width = t.height = 1;
      t.rgba = {255, 255, 255, 255};
    }
  }
  if (s.materials.empty()) s.materials.push_back(Material{"default"});
  for (Material& m : s.materials) {
    const glm::vec3 bc = m.base_color;
    for (int i = 0; i < 3; ++i) m.base_color[i] = clamp_finite(m.base_color[i], 0.0f, 1.0f, 0.8f);
    for (int i = 0; i < 3; ++i)
      m.emission[i] = clamp_finite(m.emission[i], 0.0f, std::numeric_limits<float>::max() / 16, 0.0f);
    const float metallic = m.metallic, rough = m.roughness, spec = m.specular;
    m.metallic = clamp_finite(m.metallic, 0.0f, 1.0f, 0.0f);
    // GGX with alpha -> 0 is a delta lobe the sampler cannot evaluate; 0.02 is mirror-like enough.
    m.roughness = clamp_finite(m.roughness, 0.02f, 1.0f, 1.0f);
    m.specular = clamp_finite(m.specular, 0.0f, 1.0f, 0.04f);
    // Raising a valid roughness below 0.02 to the floor is silent; anything invalid warns.
    if (bc != m.base_color || metallic != m.metallic || spec != m.specular ||
        (rough != m.roughness && !(rough >= 0.0f && rough < 0.02f)))
      rep.note("material parameter out of range, clamped");
    if (m.base_color_texture >= static_cast<int>(s.textures.size()) || m.base_color_texture < -1) {
      rep.note("material references a missing texture, dropped");
      m.base_color_texture = -1;
    }
  }

  const auto nmat = static_cast<std::uint32_t>(s.materials.size());
  const double lim = limits.max_coordinate;
  std::size_t out = 0;
  for (std::size_t t = 0; t < n; ++t) {
    glm::vec3* p = &s.positions[3 * t];
    if (!finite(p[0]) || !finite(p[1]) || !finite(p[2])) {
      rep.note("triangle with NaN/Inf position dropped");
      continue;
    }
    bool far = false;
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) far = far || std::abs(double(p[k][i])) > lim;
    if (far) {
      rep.note("triangle beyond the coordinate limit dropped");
      continue;
    }
    const glm::vec3 g = glm::cross(p[1] - p[0], p[2] - p[0]);
    const float len = glm::length(g);
    // Relative to the edge lengths, so tiny but well-shaped triangles survive.
    const float scale = std::max({glm::length(p[1] - p[0]), glm::length(p[2] - p[0]), glm::length(p[2] - p[1])});
    if (!(len > 0.0f) || !std::isfinite(len) || len <= 1e-7f * scale * scale) {
      rep.note("zero-area triangle dropped");
      continue;
    }
    const glm::vec3 gn = g / len;
    std::uint32_t mat = s.material[t];
    if (mat >= nmat) {
      rep.note("triangle with an invalid material index uses the default material");
      mat = 0;
    }
    for (int k = 0; k < 3; ++k) {
      glm::vec3 nv = s.normals[3 * t + k];
      const float nl = glm::length(nv);
      if (!finite(nv) || !(nl > 1e-12f) || !std::isfinite(nl)) {
        if (nv != glm::vec3(0)) rep.note("invalid vertex normal replaced by the face normal");
        nv = gn;
      } else {
        nv /= nl;
      }
      glm::vec2 uv = s.uvs[3 * t + k];
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
        rep.note("non-finite texture coordinate zeroed");
        uv = {0, 0};
      }
      s.positions[3 * out + k] = p[k];
      s.normals[3 * out + k] = nv;
      s.uvs[3 * out + k] = uv;
    }
    s.material[out] = mat;
    ++out;
  }
  s.positions.resize(3 * out);
  s.normals.resize(3 * out);
  s.uvs.resize(3 * out);
  s.material.resize(out);
  for (int i = 0; i < 3; ++i) s.environment[i] = clamp_finite(s.environment[i], 0.0f, 1e30f, 0.0f);
  rep.flush(s, origin);
  if (out == 0) throw core::InputError(origin + ": no renderable triangles");
}

std::pair<glm::vec3, glm::vec3> scene_bounds(const Scene& s) {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (const glm::vec3& p : s.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return {lo, hi};
}

float triangle_power(const Scene& s, std::size_t t) {
  const glm::vec3 e = s.materials[s.material[t]].emission;
  const float lum = 0.2126f * e.x + 0.7152f * e.y + 0.0722f * e.z;
  if (!(lum > 0.0f)) return 0.0f;
  const glm::vec3* p = &s.positions[3 * t];
  return 0.5f * glm::length(glm::cross(p[1] - p[0], p[2] - p[0])) * lum;
}

namespace {

// Mean and brightest texel of a texture, linear RGB (textures are sRGB-encoded RGBA8).
std::pair<glm::vec3, glm::vec3> texture_mean_max(const Texture& t) {
  float lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = core::srgb_decode(float(i) / 255.0f);
  glm::dvec3 sum(0.0);
  glm::vec3 brightest(0.0f);
  const std::size_t n = t.rgba.size() / 4;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 c(lut[t.rgba[4 * i]], lut[t.rgba[4 * i + 1]], lut[t.rgba[4 * i + 2]]);
    sum += glm::dvec3(c);
    brightest = glm::max(brightest, c);
  }
  return {n ? glm::vec3(sum / double(n)) : glm::vec3(1.0f), n ? brightest : glm::vec3(1.0f)};
}

float material_albedo(const Material& m, glm::vec3 texture) {
  const glm::vec3 base = m.base_color * texture;
  const glm::vec3 f0 = glm::mix(glm::vec3(m.specular), base, m.metallic);
  const glm::vec3 r = f0 + (1.0f - f0) * base * (1.0f - m.metallic);
  return std::clamp(std::max({r.x, r.y, r.z}), 0.0f, 1.0f);
}

}  // namespace

AlbedoStats albedo_stats(const Scene& s) {
  std::vector<std::pair<glm::vec3, glm::vec3>> tex;
  for (const Texture& t : s.textures) tex.push_back(texture_mean_max(t));
  std::vector<float> mean_of(s.materials.size()), max_of(s.materials.size());
  for (std::size_t i = 0; i < s.materials.size(); ++i) {
    const Material& m = s.materials[i];
    const bool textured = m.base_color_texture >= 0 && std::size_t(m.base_color_texture) < tex.size();
    mean_of[i] = material_albedo(m, textured ? tex[std::size_t(m.base_color_texture)].first : glm::vec3(1.0f));
    max_of[i] = material_albedo(m, textured ? tex[std::size_t(m.base_color_texture)].second : glm::vec3(1.0f));
  }
  AlbedoStats a;
  double weighted = 0, area = 0;
  for (std::size_t t = 0; t < s.material.size(); ++t) {
    const glm::vec3* p = &s.positions[3 * t];
    const double ta = 0.5 * double(glm::length(glm::cross(p[1] - p[0], p[2] - p[0])));
    weighted += ta * mean_of[s.material[t]];
    area += ta;
    a.max = std::max(a.max, max_of[s.material[t]]);
  }
  a.mean = area > 0 ? float(weighted / area) : 0.0f;
  return a;
}

}  // namespace fovea::renderer
