// Procedural scenes, the embedded default scene, and the loaders on well-formed input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"
#include "fovea/renderer/procedural.hpp"
#include "fovea/renderer/scene_io.hpp"

namespace fr = fovea::renderer;

namespace {

glm::vec3 face_normal(const fr::Scene& s, std::size_t t) {
  const glm::vec3* p = &s.positions[3 * t];
  return glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
}

std::size_t emissive_triangles(const fr::Scene& s) {
  std::size_t n = 0;
  for (std::size_t t = 0; t < s.triangle_count(); ++t) n += fr::triangle_power(s, t) > 0;
  return n;
}

}  // namespace

TEST(Scene, CornellLightFacesDownAndBoxIsClosed) {
  const fr::Scene s = fr::load_scene("cornell");
  EXPECT_EQ(s.triangle_count(), 2u * (6 + 5 + 5));
  EXPECT_TRUE(s.warnings.empty());
  ASSERT_EQ(emissive_triangles(s), 2u);
  for (std::size_t t = 0; t < s.triangle_count(); ++t)
    if (fr::triangle_power(s, t) > 0) {
      EXPECT_NEAR(face_normal(s, t).y, -1.0f, 1e-5f);
    }
  const auto [lo, hi] = fr::scene_bounds(s);
  EXPECT_NEAR(lo.x, 0.0f, 1e-6f);
  EXPECT_NEAR(hi.x, 0.556f, 1e-6f);
  EXPECT_NEAR(hi.y, 0.5488f, 1e-6f);
  EXPECT_NEAR(hi.z, 0.5592f, 1e-6f);
}

TEST(Scene, MirroredCornellReflectsGeometryAndKeepsFacing) {
  const fr::Scene a = fr::make_cornell(false), b = fr::make_cornell(true);
  ASSERT_EQ(a.triangle_count(), b.triangle_count());
  for (std::size_t t = 0; t < a.triangle_count(); ++t) {
    EXPECT_NEAR(a.positions[3 * t].x, 0.556f - b.positions[3 * t].x, 1e-6f);
    const glm::vec3 na = face_normal(a, t), nb = face_normal(b, t);
    EXPECT_NEAR(na.x, -nb.x, 1e-5f);
    EXPECT_NEAR(na.y, nb.y, 1e-5f);
  }
}

TEST(Scene, FurnaceIsAClosedInwardFacingEmitter) {
  const fr::Scene s = fr::load_scene("furnace");
  EXPECT_EQ(emissive_triangles(s), s.triangle_count());
  for (std::size_t t = 0; t < s.triangle_count(); ++t) {
    const glm::vec3* p = &s.positions[3 * t];
    const glm::vec3 centroid = (p[0] + p[1] + p[2]) / 3.0f;
    EXPECT_LT(glm::dot(face_normal(s, t), centroid), 0.0f) << t;  // front faces the centre
  }
  EXPECT_EQ(s.materials[0].specular, 0.0f);
  EXPECT_EQ(s.materials[0].base_color, glm::vec3(0.5f));
}

TEST(Scene, GlossySpheresAndOccludersHaveTheirFeatures) {
  const fr::Scene g = fr::load_scene("glossy-spheres");
  int ggx = 0;
  for (const auto& m : g.materials) ggx += m.metallic == 1.0f;
  EXPECT_EQ(ggx, 5);
  EXPECT_EQ(emissive_triangles(g), 4u);
  const fr::Scene o = fr::load_scene("stereo-occluders");
  EXPECT_EQ(o.textures.size(), 1u);
  EXPECT_GT(emissive_triangles(o), 0u);
}

TEST(Scene, DefaultGltfSceneIsSmallTexturedAndLit) {
  const fr::Scene s = fr::load_scene("default");
  EXPECT_GE(s.triangle_count(), 1000u);
  EXPECT_LE(s.triangle_count(), 10000u);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 64);
  bool strength = false;
  for (const auto& m : s.materials) strength = strength || std::abs(m.emission.x - 12.0f) < 1e-4f;
  EXPECT_TRUE(strength) << "KHR_materials_emissive_strength not applied";
  EXPECT_NEAR(s.camera.position.y, 1.5, 1e-6);
  EXPECT_NEAR(s.camera.position.z, 2.2, 1e-6);
  // Transforms: the props group is offset by z = -1.2 and the sphere by x = -0.9.
  const auto [lo, hi] = fr::scene_bounds(s);
  EXPECT_NEAR(lo.x, -3.0f, 1e-4f);
  EXPECT_NEAR(hi.y, 3.0f, 1e-4f);
  const char* src = std::getenv("FOVEA_SOURCE_DIR");
  ASSERT_NE(src, nullptr) << "FOVEA_SOURCE_DIR not set";
  const auto file = std::filesystem::path(src) / "data/scenes/default.gltf";
  EXPECT_LT(std::filesystem::file_size(file), 500u * 1024u);
  const fr::Scene f = fr::load_scene(file.string());
  EXPECT_EQ(f.triangle_count(), s.triangle_count());
}

TEST(Scene, ObjWithMtlReadsMaterials) {
  const auto dir = std::filesystem::temp_directory_path() / "fovea_obj_test";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "m.mtl") << "newmtl lamp\nKd 0.2 0.3 0.4\nKs 0.5 0.5 0.5\nNs 100\nKe 5 4 3\n";
  std::ofstream(dir / "m.obj") << "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nusemtl lamp\nf 1 2 3\nf 2 4 3\n";
  const fr::Scene s = fr::load_scene((dir / "m.obj").string());
  ASSERT_EQ(s.triangle_count(), 2u);
  const auto& m = s.materials[s.material[0]];
  EXPECT_EQ(m.base_color, glm::vec3(0.2f, 0.3f, 0.4f));
  EXPECT_FLOAT_EQ(m.specular, 0.5f);
  EXPECT_NEAR(m.roughness, std::sqrt(std::sqrt(2.0f / 102.0f)), 1e-6f);
  EXPECT_EQ(m.emission, glm::vec3(5, 4, 3));
  std::filesystem::remove_all(dir);
}

TEST(Scene, GltfDoubleSidedIsReadAndDefaultsToFalse) {
  // Two one-triangle primitives: material 0 double-sided, material 1 without the flag.
  const auto dir = std::filesystem::temp_directory_path() / "fovea_gltf_sides_test";
  std::filesystem::create_directories(dir);
  const float pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::ofstream(dir / "t.bin", std::ios::binary).write(reinterpret_cast<const char*>(pos), sizeof(pos));
  std::ofstream(dir / "t.gltf") << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0}, {"mesh": 1}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]},
               {"primitives": [{"attributes": {"POSITION": 0}, "material": 1}]}],
    "materials": [{"name": "two", "doubleSided": true}, {"name": "one"}],
    "buffers": [{"uri": "t.bin", "byteLength": 36}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]}]})";
  const fr::Scene s = fr::load_scene((dir / "t.gltf").string());
  ASSERT_EQ(s.triangle_count(), 2u);
  for (std::size_t t = 0; t < 2; ++t) {
    const fr::Material& m = s.materials[s.material[t]];
    EXPECT_EQ(m.double_sided, m.name == "two") << m.name;
  }
  std::filesystem::remove_all(dir);
}

// Triangle strips and fans (glTF 2.0 §3.7.2.1) become triangle lists with each triangle's
// winding kept: the glTF Asset Generator's Mesh_PrimitiveMode models (Debian's
// assimp-testmodels) draw the same square as a list (06; 13 and 14 indexed), a strip (04; 11
// indexed) and a fan (05; 12 indexed); point and line primitives (00-03, 07-10) have none.
TEST(Scene, GltfStripsAndFansAreTheListsTriangles) {
  const std::filesystem::path dir = "/usr/share/assimp/models/glTF2/glTF-Asset-Generator/Mesh_PrimitiveMode";
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << "install Debian's assimp-testmodels (./x deps)";
  const auto load = [&](const char* n) {
    return fr::load_scene((dir / ("Mesh_PrimitiveMode_" + std::string(n) + ".gltf")).string());
  };
  // Area and facing: twice the area vector of each triangle, summed.
  const auto area = [](const fr::Scene& s) {
    glm::dvec3 a(0);
    for (std::size_t t = 0; t < s.triangle_count(); ++t) {
      const glm::dvec3 p0 = s.positions[3 * t], p1 = s.positions[3 * t + 1], p2 = s.positions[3 * t + 2];
      a += glm::cross(p1 - p0, p2 - p0);
    }
    return a;
  };
  const fr::Scene list = load("06");
  ASSERT_EQ(list.triangle_count(), 2u);
  const glm::dvec3 expected = area(list);
  ASSERT_GT(glm::length(expected), 0.0);
  for (const char* n : {"04", "05", "11", "12", "13", "14"}) {
    const fr::Scene s = load(n);
    ASSERT_EQ(s.triangle_count(), 2u) << n;
    EXPECT_NEAR(glm::length(area(s) - expected), 0.0, 1e-6) << n;
    for (std::size_t t = 0; t < 2; ++t) {  // each triangle faces as the list's do
      const glm::dvec3 p0 = s.positions[3 * t], p1 = s.positions[3 * t + 1], p2 = s.positions[3 * t + 2];
      EXPECT_GT(glm::dot(glm::cross(p1 - p0, p2 - p0), expected), 0.0) << n << ", triangle " << t;
    }
  }
  for (const char* n : {"00", "01", "02", "03", "07", "08", "09", "10"})
    EXPECT_THROW(load(n), fovea::core::InputError) << n;
}

TEST(Scene, UnknownNameIsAnInputError) {
  EXPECT_THROW(fr::load_scene("no-such-scene"), fovea::core::InputError);
  EXPECT_THROW(fr::load_scene("/nonexistent/x.gltf"), fovea::core::InputError);
}
