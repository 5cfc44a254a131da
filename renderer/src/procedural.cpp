#include "fovea/renderer/procedural.hpp"

#include <cmath>
#include <numbers>
#include <utility>

#include <glm/geometric.hpp>

namespace fovea::renderer {

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

Material diffuse(const char* name, glm::vec3 albedo) {
  Material m;
  m.name = name;
  m.base_color = albedo;
  m.specular = 0.0f;  // pure Lambert, as in the measured data
  return m;
}

Material emitter(const char* name, glm::vec3 radiance) {
  Material m = diffuse(name, glm::vec3(0.78f));
  m.emission = radiance;
  m.double_sided = false;  // area lights emit from their front face only
  return m;
}

// Rotation of 180° about +Y: view -Z (OpenXR forward) becomes world +Z.
const glm::dquat kLookPlusZ{0.0, 0.0, 1.0, 0.0};

}  // namespace

void add_sphere(Scene& s, glm::vec3 c, float r, std::uint32_t mat, int rings, int segments, bool inward) {
  auto point = [&](int i, int j) {
    const float th = kPi * float(i) / float(rings), ph = 2.0f * kPi * float(j) / float(segments);
    return glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const glm::vec3 a = point(i, j), b = point(i + 1, j), cc = point(i + 1, j + 1), d = point(i, j + 1);
      const float sn = inward ? -1.0f : 1.0f;
      auto tri = [&](glm::vec3 p, glm::vec3 q, glm::vec3 w) {
        if (inward) std::swap(q, w);
        s.add_triangle(c + r * p, c + r * q, c + r * w, mat, sn * p, sn * q, sn * w);
      };
      // Outward winding seen from outside: a, d, b (counter-clockwise).
      if (i != 0) tri(a, d, cc);
      if (i != rings - 1) tri(a, cc, b);
    }
}

void add_box(Scene& s, glm::vec3 lo, glm::vec3 hi, std::uint32_t mat) {
  const glm::vec3 v[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  // Counter-clockwise seen from outside.
  s.add_quad(v[0], v[3], v[2], v[1], mat);  // -z
  s.add_quad(v[4], v[5], v[6], v[7], mat);  // +z
  s.add_quad(v[0], v[4], v[7], v[3], mat);  // -x
  s.add_quad(v[1], v[2], v[6], v[5], mat);  // +x
  s.add_quad(v[0], v[1], v[5], v[4], mat);  // -y
  s.add_quad(v[3], v[7], v[6], v[2], mat);  // +y
}

Scene make_cornell(bool mirrored) {
  Scene s;
  s.name = mirrored ? "cornell-mirrored" : "cornell";
  // Reflectances and light radiance commonly used with the measured geometry.
  const auto white = s.add_material(diffuse("white", {0.73f, 0.73f, 0.73f}));
  const auto red = s.add_material(diffuse("red", {0.63f, 0.065f, 0.05f}));
  const auto green = s.add_material(diffuse("green", {0.14f, 0.45f, 0.091f}));
  const auto light = s.add_material(emitter("light", {17.0f, 12.0f, 4.0f}));
  auto q = [&](std::uint32_t m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    s.add_quad(a * 1e-3f, b * 1e-3f, c * 1e-3f, d * 1e-3f, m);
  };
  q(white, {552.8f, 0, 0}, {0, 0, 0}, {0, 0, 559.2f}, {549.6f, 0, 559.2f});                     // floor
  q(white, {556, 548.8f, 0}, {556, 548.8f, 559.2f}, {0, 548.8f, 559.2f}, {0, 548.8f, 0});       // ceiling
  q(white, {549.6f, 0, 559.2f}, {0, 0, 559.2f}, {0, 548.8f, 559.2f}, {556, 548.8f, 559.2f});    // back
  q(green, {0, 0, 559.2f}, {0, 0, 0}, {0, 548.8f, 0}, {0, 548.8f, 559.2f});                     // right
  q(red, {552.8f, 0, 0}, {549.6f, 0, 559.2f}, {556, 548.8f, 559.2f}, {556, 548.8f, 0});         // left
  // The measured light lies in the ceiling plane; 0.1 mm lower avoids coplanar fighting.
  q(light, {343, 548.7f, 227}, {343, 548.7f, 332}, {213, 548.7f, 332}, {213, 548.7f, 227});
  // Short block.
  q(white, {130, 165, 65}, {82, 165, 225}, {240, 165, 272}, {290, 165, 114});
  q(white, {290, 0, 114}, {290, 165, 114}, {240, 165, 272}, {240, 0, 272});
  q(white, {130, 0, 65}, {130, 165, 65}, {290, 165, 114}, {290, 0, 114});
  q(white, {82, 0, 225}, {82, 165, 225}, {130, 165, 65}, {130, 0, 65});
  q(white, {240, 0, 272}, {240, 165, 272}, {82, 165, 225}, {82, 0, 225});
  // Tall block.
  q(white, {423, 330, 247}, {265, 330, 296}, {314, 330, 456}, {472, 330, 406});
  q(white, {423, 0, 247}, {423, 330, 247}, {472, 330, 406}, {472, 0, 406});
  q(white, {472, 0, 406}, {472, 330, 406}, {314, 330, 456}, {314, 0, 456});
  q(white, {314, 0, 456}, {314, 330, 456}, {265, 330, 296}, {265, 0, 296});
  q(white, {265, 0, 296}, {265, 330, 296}, {423, 330, 247}, {423, 0, 247});
  // The camera of the measured data sits at z = -0.8 with a 39° FOV; HMD fields of view
  // are ~100°, so the eye moves closer to keep the box filling the view.
  s.camera.position = {0.278, 0.273, -0.25};
  s.camera.orientation = kLookPlusZ;
  if (mirrored) {
    // Reflect about the camera's plane x = 0.278; reversing the winding keeps faces'
    // front sides (the light still emits downwards).
    const float cx = 0.278f;
    for (std::size_t t = 0; t < s.triangle_count(); ++t) {
      for (int k = 0; k < 3; ++k) s.positions[3 * t + k].x = 2 * cx - s.positions[3 * t + k].x;
      std::swap(s.positions[3 * t + 1], s.positions[3 * t + 2]);
      std::swap(s.uvs[3 * t + 1], s.uvs[3 * t + 2]);
    }
  }
  return s;
}

Scene make_furnace(float albedo, float emission) {
  Scene s;
  s.name = "furnace";
  Material m = diffuse("furnace", glm::vec3(albedo));
  m.emission = glm::vec3(emission);
  const auto mat = s.add_material(m);
  add_sphere(s, {0, 0, 0}, 1.0f, mat, 12, 24, true);
  // Flat shading normals: interpolated normals would break energy balance in the enclosure.
  for (auto& n : s.normals) n = glm::vec3(0);
  return s;
}

Scene make_glossy_spheres() {
  Scene s;
  s.name = "glossy-spheres";
  s.environment = glm::vec3(0.03f);
  const auto floor = s.add_material(diffuse("floor", {0.5f, 0.5f, 0.5f}));
  s.add_quad({-4, 0, 1}, {4, 0, 1}, {4, 0, -6}, {-4, 0, -6}, floor);
  const float rough[5] = {0.05f, 0.15f, 0.3f, 0.5f, 0.8f};
  const glm::vec3 colour[5] = {{0.95f, 0.64f, 0.54f}, {0.91f, 0.92f, 0.92f}, {1.0f, 0.78f, 0.34f},
                               {0.95f, 0.64f, 0.54f}, {0.91f, 0.92f, 0.92f}};
  for (int i = 0; i < 5; ++i) {
    Material m;
    m.name = "ggx-" + std::to_string(i);
    m.base_color = colour[i];
    m.metallic = 1.0f;
    m.roughness = rough[i];
    add_sphere(s, {-1.6f + 0.8f * float(i), 0.35f, -2.6f}, 0.35f, s.add_material(m), 16, 32);
  }
  // A large warm light and a small bright cool one, facing down.
  const auto warm = s.add_material(emitter("warm", {6.0f, 5.0f, 3.5f}));
  const auto cool = s.add_material(emitter("cool", {20.0f, 24.0f, 36.0f}));
  s.add_quad({-2.0f, 2.5f, -3.5f}, {-0.5f, 2.5f, -3.5f}, {-0.5f, 2.5f, -2.0f}, {-2.0f, 2.5f, -2.0f}, warm);
  s.add_quad({1.2f, 1.8f, -2.2f}, {1.6f, 1.8f, -2.2f}, {1.6f, 1.8f, -1.8f}, {1.2f, 1.8f, -1.8f}, cool);
  s.camera.position = {0, 0.9, 0};
  s.camera.orientation = glm::angleAxis(-0.2, glm::dvec3(1, 0, 0));  // tilted slightly down
  return s;
}

Scene make_stereo_occluders() {
  Scene s;
  s.name = "stereo-occluders";
  s.environment = glm::vec3(0.05f);
  // A checkerboard on the back wall makes disocclusion errors visible.
  Texture checker;
  checker.name = "checker";
  checker.width = checker.height = 64;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const std::uint8_t v = ((x / 8 + y / 8) % 2) ? 230 : 40;
      checker.rgba.insert(checker.rgba.end(), {v, v, v, 255});
    }
  s.textures.push_back(std::move(checker));
  Material wall = diffuse("back-wall", {1, 1, 1});
  wall.base_color_texture = 0;
  const auto wall_m = s.add_material(wall);
  const auto floor_m = s.add_material(diffuse("floor", {0.45f, 0.4f, 0.35f}));
  const auto pillar_m = s.add_material(diffuse("pillar", {0.7f, 0.2f, 0.15f}));
  const auto light_m = s.add_material(emitter("light", {8, 8, 8}));
  s.add_quad({-3, -1.6f, -4}, {3, -1.6f, -4}, {3, 2, -4}, {-3, 2, -4}, wall_m);
  s.add_quad({-3, -1.6f, 0.5f}, {3, -1.6f, 0.5f}, {3, -1.6f, -4}, {-3, -1.6f, -4}, floor_m);
  // Pillars 3 cm wide, 0.45…0.9 m from the eyes: ~4° of disparity between the eyes.
  for (int i = 0; i < 5; ++i) {
    const float x = -0.36f + 0.18f * float(i), z = -0.45f - 0.11f * float(i);
    add_box(s, {x - 0.015f, -1.6f, z - 0.015f}, {x + 0.015f, 1.2f, z + 0.015f}, pillar_m);
  }
  s.add_quad({-1, 1.9f, -3}, {1, 1.9f, -3}, {1, 1.9f, -1.5f}, {-1, 1.9f, -1.5f}, light_m);  // faces down
  return s;
}

}  // namespace fovea::renderer
