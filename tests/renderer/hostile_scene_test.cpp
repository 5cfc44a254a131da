// Bad and hostile scene files: each is loaded with the offending part dropped (and a
// warning) or refused with core::InputError; never a crash.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "fovea/core/error.hpp"
#include "fovea/renderer/scene_io.hpp"

namespace fr = fovea::renderer;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string base64(const std::vector<std::uint8_t>& d) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < d.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t(d[i]) << 16) | (i + 1 < d.size() ? d[i + 1] << 8 : 0) |
                            (i + 2 < d.size() ? d[i + 2] : 0);
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += i + 1 < d.size() ? t[(v >> 6) & 63] : '=';
    out += i + 2 < d.size() ? t[v & 63] : '=';
  }
  return out;
}

// A one-mesh glTF: `pos` (xyz triples) and uint32 `idx` in one data-URI buffer.
json make_gltf(const std::vector<float>& pos, const std::vector<std::uint32_t>& idx) {
  std::vector<std::uint8_t> bytes(pos.size() * 4 + idx.size() * 4);
  std::memcpy(bytes.data(), pos.data(), pos.size() * 4);
  std::memcpy(bytes.data() + pos.size() * 4, idx.data(), idx.size() * 4);
  json j;
  j["asset"] = {{"version", "2.0"}};
  j["buffers"] = json::array({{{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}}});
  j["bufferViews"] = json::array({{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", pos.size() * 4}},
                                  {{"buffer", 0}, {"byteOffset", pos.size() * 4}, {"byteLength", idx.size() * 4}}});
  j["accessors"] = json::array({{{"bufferView", 0}, {"componentType", 5126}, {"count", pos.size() / 3}, {"type", "VEC3"}},
                                {{"bufferView", 1}, {"componentType", 5125}, {"count", idx.size()}, {"type", "SCALAR"}}});
  j["meshes"] = json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}})}}});
  j["nodes"] = json::array({{{"mesh", 0}}});
  j["scenes"] = json::array({{{"nodes", json::array({0})}}});
  j["scene"] = 0;
  return j;
}

const std::vector<float> kTwoTris = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
const std::vector<std::uint32_t> kTwoIdx = {0, 1, 2, 1, 3, 2};

class Hostile : public ::testing::Test {
 protected:
  fs::path dir = fs::temp_directory_path() / ("fovea_hostile_" + std::to_string(::getpid()));
  void SetUp() override { fs::create_directories(dir); }
  void TearDown() override { fs::remove_all(dir); }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name, std::ios::binary) << text;
    return (dir / name).string();
  }
  std::string write(const std::string& name, const json& j) { return write(name, j.dump()); }
};

bool has_warning(const fr::Scene& s, const std::string& what) {
  for (const auto& w : s.warnings)
    if (w.find(what) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST_F(Hostile, OutOfRangeIndicesDropTheirTriangles) {
  const fr::Scene s = fr::load_scene(write("a.gltf", make_gltf(kTwoTris, {0, 1, 2, 1, 99, 2})));
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(s, "out-of-range indices")) << s.warnings.size();
}

TEST_F(Hostile, NanAndInfPositionsDropTheirTriangles) {
  std::vector<float> p = kTwoTris;
  p[9] = std::numeric_limits<float>::quiet_NaN();
  p[10] = std::numeric_limits<float>::infinity();
  const fr::Scene s = fr::load_scene(write("a.gltf", make_gltf(p, kTwoIdx)));
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(s, "NaN/Inf"));
}

TEST_F(Hostile, AllTrianglesBadIsRefused) {
  const std::string f = write("a.gltf", make_gltf(kTwoTris, {5, 6, 7}));
  EXPECT_THROW(fr::load_scene(f), fovea::core::InputError);
}

TEST_F(Hostile, ZeroAreaTrianglesAreDropped) {
  const fr::Scene s = fr::load_scene(write("a.gltf", make_gltf(kTwoTris, {0, 1, 2, 0, 0, 1, 1, 1, 1})));
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(s, "zero-area"));
}

TEST_F(Hostile, HugeCoordinatesLoadAndAbsurdOnesAreDropped) {
  std::vector<float> p = kTwoTris;
  for (float& v : p) v = v * 1e7f + 3e7f;
  fr::Scene s = fr::load_scene(write("a.gltf", make_gltf(p, kTwoIdx)));
  EXPECT_EQ(s.triangle_count(), 2u);
  p[9] = 1e30f;
  s = fr::load_scene(write("b.gltf", make_gltf(p, kTwoIdx)));
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(s, "coordinate limit"));
}

TEST_F(Hostile, MissingBufferIsRefused) {
  json j = make_gltf(kTwoTris, kTwoIdx);
  j["buffers"][0]["uri"] = "missing.bin";
  EXPECT_THROW(fr::load_scene(write("a.gltf", j)), fovea::core::InputError);
}

TEST_F(Hostile, AccessorBeyondItsBufferSkipsThePrimitive) {
  json j = make_gltf(kTwoTris, kTwoIdx);
  j["accessors"][0]["byteOffset"] = 1u << 30;
  EXPECT_THROW(fr::load_scene(write("a.gltf", j)), fovea::core::InputError);
  j = make_gltf(kTwoTris, kTwoIdx);
  j["accessors"][1]["count"] = 4000000000u;
  EXPECT_THROW(fr::load_scene(write("b.gltf", j)), fovea::core::InputError);
  j = make_gltf(kTwoTris, kTwoIdx);
  j["bufferViews"][0]["buffer"] = 7;
  EXPECT_THROW(fr::load_scene(write("c.gltf", j)), fovea::core::InputError);
}

TEST_F(Hostile, MissingTextureBecomesWhiteWithAWarning) {
  json j = make_gltf(kTwoTris, kTwoIdx);
  j["images"] = json::array({{{"uri", "nope.png"}}});
  j["textures"] = json::array({{{"source", 0}}, {{"source", 5}}});
  j["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1}}}}}}});
  j["meshes"][0]["primitives"][0]["material"] = 0;
  const fr::Scene s = fr::load_scene(write("a.gltf", j));
  EXPECT_EQ(s.triangle_count(), 2u);
  ASSERT_EQ(s.textures.size(), 2u);
  EXPECT_EQ(s.textures[0].width, 1);
  EXPECT_FALSE(s.warnings.empty());
}

TEST_F(Hostile, RecursiveNodeGraphIsCut) {
  json j = make_gltf(kTwoTris, kTwoIdx);
  j["nodes"] = json::array({{{"mesh", 0}, {"children", {1}}}, {{"children", {0, 1, 42}}}});
  const fr::Scene s = fr::load_scene(write("a.gltf", j));
  EXPECT_EQ(s.triangle_count(), 2u);
  EXPECT_TRUE(has_warning(s, "cycle"));
}

TEST_F(Hostile, ExponentialInstancingIsRefused) {
  json j = make_gltf(kTwoTris, kTwoIdx);
  json nodes = json::array();
  for (int i = 0; i < 40; ++i) nodes.push_back({{"children", {i + 1, i + 1}}});
  nodes.push_back({{"mesh", 0}});
  j["nodes"] = nodes;
  fr::SceneLimits lim;
  lim.max_triangles = 100000;
  EXPECT_THROW(fr::load_scene(write("a.gltf", j), lim), fovea::core::InputError);
}

TEST_F(Hostile, NonFiniteTransformSkipsTheSubtree) {
  json j = make_gltf(kTwoTris, kTwoIdx);
  j["nodes"] = json::array({{{"mesh", 0}}, {{"mesh", 0}, {"scale", {1e308, 1e308, 1e308}}, {"children", {0}}}});
  j["scenes"][0]["nodes"] = {0, 1};
  const fr::Scene s = fr::load_scene(write("a.gltf", j));
  EXPECT_EQ(s.triangle_count(), 2u);
}

TEST_F(Hostile, GarbageFilesAreRefused) {
  EXPECT_THROW(fr::load_scene(write("empty.gltf", std::string())), fovea::core::InputError);
  EXPECT_THROW(fr::load_scene(write("junk.gltf", std::string("{\"asset\": [1, 2"))), fovea::core::InputError);
  EXPECT_THROW(fr::load_scene(write("junk.glb", std::string("glTF\x02\0\0\0\xff\xff\xff\x7f", 12))),
               fovea::core::InputError);
  EXPECT_THROW(fr::load_scene(write("empty.obj", std::string())), fovea::core::InputError);
  EXPECT_THROW(fr::load_scene(write("wrong.gltf", json{{"asset", {{"version", 7}}}, {"meshes", 3}})),
               fovea::core::InputError);
}

TEST_F(Hostile, ObjWithBadIndicesLoadsTheRest) {
  const std::string f = write("a.obj",
                              std::string("mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\n"
                              "f 1 2 3\nf 1 2 99\nf 1 2 4\nf -1 -2 -3\nf 1//7 2//1 3//1\nusemtl nothing\nf 3 2 1\n"));
  const fr::Scene s = fr::load_scene(f);
  EXPECT_GE(s.triangle_count(), 2u);
  EXPECT_FALSE(s.warnings.empty());
}

// Fuzz findings: each input refused with a message naming the file, or loaded with the
// bad part dropped; none may crash, hang or allocate without bound.

// The message a refused scene gives ("accepted" if it loads).
std::string refusal(const std::string& path, const fr::SceneLimits& limits = {}) {
  try {
    fr::load_scene(path, limits);
  } catch (const fovea::core::InputError& e) {
    return e.what();
  }
  return "accepted";
}

namespace {

// A one-triangle glTF in `dir`: 16-bit integer positions (0,0,0), (100,0,0), (0,100,0) under a
// node scaled by 0.01, with the given asset object and required extensions (JSON array items).
std::string integer_triangle(const fs::path& dir, const std::string& asset, const std::string& required) {
  const std::int16_t pos[10] = {0, 0, 0, 100, 0, 0, 0, 100, 0, 0};  // three SHORT VEC3, padded to 4 bytes
  std::ofstream(dir / "q.bin", std::ios::binary).write(reinterpret_cast<const char*>(pos), sizeof(pos));
  std::ofstream(dir / "q.gltf") << R"({"asset": )" + asset + R"(, "scene": 0, "scenes": [{"nodes": [0]}],
    "extensionsUsed": [)" + required + R"(], "extensionsRequired": [)" + required + R"(],
    "nodes": [{"mesh": 0, "scale": [0.01, 0.01, 0.01]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"uri": "q.bin", "byteLength": 20}],
    "bufferViews": [{"buffer": 0, "byteLength": 20}],
    "accessors": [{"bufferView": 0, "componentType": 5122, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [100, 100, 0]}]})";
  return (dir / "q.gltf").string();
}

}  // namespace

// extensionsRequired (glTF 2.0 §3.12): an asset that requires an extension this loader does
// not read is refused, naming it, also when the parser cannot load the file without it (a
// Draco-compressed mesh); KHR_mesh_quantization is read: 16-bit integer positions.
TEST_F(Hostile, GltfRequiredExtensionsAreReadOrRefusedByName) {
  const fr::Scene s = fr::load_scene(integer_triangle(dir, R"({"version": "2.0"})", R"("KHR_mesh_quantization")"));
  ASSERT_EQ(s.triangle_count(), 1u);
  EXPECT_NEAR(glm::length(s.positions[1] - glm::vec3(1, 0, 0)), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::length(s.positions[2] - glm::vec3(0, 1, 0)), 0.0f, 1e-6f);
  EXPECT_NE(refusal(integer_triangle(dir, R"({"version": "2.0"})", R"("KHR_mesh_quantization", "EXT_not_read_here")"))
                .find("requires the glTF extension(s) EXT_not_read_here"),
            std::string::npos);
  const std::string draco = "/usr/share/assimp/models/glTF2/draco/2CylinderEngine.gltf";
  if (fs::exists(draco)) {
    EXPECT_NE(refusal(draco).find("KHR_draco_mesh_compression"), std::string::npos);
  }
}

// The asset's version (glTF 2.0 §3.2): a 2.x asset loads (minor versions are backward
// compatible), one that needs a 2.1 reader (minVersion) or has another major version does not.
TEST_F(Hostile, GltfVersionsAreCheckedAsTheSpecificationSays) {
  const auto with = [&](const std::string& asset) {
    return refusal(integer_triangle(dir, asset, R"("KHR_mesh_quantization")"));
  };
  EXPECT_EQ(with(R"({"version": "2.1"})"), "accepted");
  EXPECT_EQ(with(R"({"version": "2.1", "minVersion": "2.0"})"), "accepted");
  EXPECT_NE(with(R"({"version": "2.1", "minVersion": "2.1"})").find("needs a reader of glTF 2.1"), std::string::npos);
  EXPECT_NE(with(R"({"version": "3.0"})").find("glTF version \"3.0\""), std::string::npos);
  EXPECT_NE(with(R"({"version": "1.0"})").find("glTF version \"1.0\""), std::string::npos);
  EXPECT_NE(with(R"({"version": "two"})").find("glTF version \"two\""), std::string::npos);
}

// A binary PPM (stb_image decodes PNM): the smallest image to put in a data URI.
std::string ppm_data_uri(int w, int h) {
  const std::string header = "P6\n" + std::to_string(w) + " " + std::to_string(h) + "\n255\n";
  std::vector<std::uint8_t> bytes(header.begin(), header.end());
  bytes.resize(bytes.size() + std::size_t(w) * h * 3, 200);
  return "data:application/octet-stream;base64," + base64(bytes);
}

// A one-material scene whose base colour uses texture 0 -> image 0.
json textured(const json& image) {
  json j = make_gltf(kTwoTris, kTwoIdx);
  j["images"] = json::array({image});
  j["textures"] = json::array({{{"source", 0}}});
  j["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}});
  j["meshes"][0]["primitives"][0]["material"] = 0;
  return j;
}

// Sparse accessors (glTF 2.0 §3.6.2.3): values substituted at their indices, over the dense
// values or over zeros without a bufferView; an index past the accessor's count drops the
// primitive with a warning.
TEST_F(Hostile, SparseAccessorsSubstituteTheirValues) {
  const auto with_sparse = [](json j, const std::vector<std::uint8_t>& at, const std::vector<float>& values) {
    std::vector<std::uint8_t> bytes(4 + values.size() * 4, 0);  // the indices, padded to 4 bytes; the values
    std::memcpy(bytes.data(), at.data(), at.size());
    std::memcpy(bytes.data() + 4, values.data(), values.size() * 4);
    j["buffers"].push_back(
        {{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}});
    j["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 0}, {"byteLength", at.size()}});
    j["bufferViews"].push_back({{"buffer", 1}, {"byteOffset", 4}, {"byteLength", values.size() * 4}});
    j["accessors"][0]["sparse"] = {{"count", at.size()},
                                   {"indices", {{"bufferView", 2}, {"componentType", 5121}}},
                                   {"values", {{"bufferView", 3}}}};
    return j;
  };
  const std::vector<std::uint32_t> idx = {0, 1, 2, 1, 3, 2};
  const fr::Scene dense = fr::load_scene(write("dense.gltf", make_gltf(kTwoTris, idx)));
  ASSERT_EQ(dense.triangle_count(), 2u);
  // Over the dense values: vertex 3 moves from (1, 1, 0) to (2, 2, 0).
  const fr::Scene moved = fr::load_scene(write("moved.gltf", with_sparse(make_gltf(kTwoTris, idx), {3}, {2, 2, 0})));
  ASSERT_EQ(moved.triangle_count(), 2u);
  EXPECT_EQ(moved.positions[4], glm::vec3(2, 2, 0));
  EXPECT_EQ(moved.positions[0], dense.positions[0]);
  // Over zeros: the same square as the dense accessor.
  json zeros = with_sparse(make_gltf(kTwoTris, idx), {1, 2, 3}, {1, 0, 0, 0, 1, 0, 1, 1, 0});
  zeros["accessors"][0].erase("bufferView");
  const fr::Scene from_zeros = fr::load_scene(write("zeros.gltf", zeros));
  EXPECT_EQ(from_zeros.positions, dense.positions);
  // An index past the count: the primitive is dropped, and with it the only one.
  EXPECT_NE(refusal(write("past.gltf", with_sparse(make_gltf(kTwoTris, idx), {7}, {2, 2, 0}))).find("no renderable"),
            std::string::npos);
}

TEST_F(Hostile, ImageBufferViewPastItsBufferIsNotDecoded) {
  json j = textured({{"bufferView", 2}, {"mimeType", "image/png"}});
  j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 40}, {"byteLength", 1000000}});
  const fr::Scene s = fr::load_scene(write("a.gltf", j));
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 1);
  EXPECT_TRUE(has_warning(s, "outside its buffer"));
  j["bufferViews"][2] = {{"buffer", 0}, {"byteOffset", 1u << 31}, {"byteLength", 16}};
  EXPECT_TRUE(has_warning(fr::load_scene(write("b.gltf", j)), "outside its buffer"));
  j["bufferViews"][2]["buffer"] = 9;  // tinygltf itself checks the buffer index
  EXPECT_THROW(fr::load_scene(write("c.gltf", j)), fovea::core::InputError);
}

TEST_F(Hostile, DeeplyNestedExtrasAreRefusedBeforeParsing) {
  std::string text = make_gltf(kTwoTris, kTwoIdx).dump();
  text.insert(1, "\"extras\":" + std::string(20000, '[') + std::string(20000, ']') + ",");
  const std::string e = refusal(write("deep.gltf", text));
  EXPECT_NE(e.find("deep.gltf: JSON nested deeper than"), std::string::npos) << e;
}

TEST_F(Hostile, NodeGraphWalkIsBoundedEvenWithoutTriangles) {
  json j = make_gltf(kTwoTris, kTwoIdx);
  json nodes = json::array();
  for (int i = 0; i < 40; ++i) nodes.push_back({{"children", {i + 1, i + 1}}});
  nodes.push_back(json::object());  // the leaf holds nothing: no triangle budget is reached
  j["nodes"] = nodes;
  const std::string e = refusal(write("dag.gltf", j));
  EXPECT_NE(e.find("node instances"), std::string::npos) << e;
}

TEST_F(Hostile, OnlyUsedTexturesAreDecodedWithinABudget) {
  json j = textured({{"uri", ppm_data_uri(32, 32)}});
  fr::SceneLimits lim;
  lim.max_texture_bytes = 32 * 32 * 4;
  fr::Scene s = fr::load_scene(write("a.gltf", j), lim);
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].width, 32);
  EXPECT_EQ(s.textures[0].rgba[0], 200);
  // Ten more large images and textures nobody uses: not decoded, so within the budget.
  for (int i = 0; i < 10; ++i) {
    j["images"].push_back({{"uri", ppm_data_uri(256, 256)}});
    j["textures"].push_back({{"source", i + 1}});
  }
  s = fr::load_scene(write("b.gltf", j), lim);
  EXPECT_EQ(s.textures.size(), 11u);
  EXPECT_EQ(s.textures[5].width, 1);
  // Used, they exceed it: refused naming the file.
  j["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 3}}}}}});
  const std::string e = refusal(write("c.gltf", j), lim);
  EXPECT_NE(e.find("c.gltf: textures need more than"), std::string::npos) << e;
}

TEST_F(Hostile, ObjExponentOverflowIsRefusedNamingTheLine) {
  for (const char* bad : {"1e99999999999", "-2.5E+0000000012345", "1e-2147483649"}) {
    const std::string f = write("e.obj", std::string("v 0 0 0\nv 1 0 0\nv 0 ") + bad + " 0\nf 1 2 3\n");
    const std::string e = refusal(f);
    EXPECT_NE(e.find("e.obj:3: number with an exponent out of range"), std::string::npos) << bad << ": " << e;
  }
  // Ordinary exponents and names that merely contain an "e" load.
  const std::string ok = write("ok.obj", std::string("o e1234567\nv 0 0 0\nv 1e0 0 0\nv 0 1.0e-000003 0\nv 0 100e-2 0\nf 1 2 4\n"));
  EXPECT_EQ(fr::load_scene(ok).triangle_count(), 1u);
}

// tinyobjloader reads "nan"/"inf" as 0: `v nan nan nan` became the origin, unseen by the
// scene's NaN check. Refused naming the file and line; names may still spell "nan".
TEST_F(Hostile, ObjNonFiniteNumbersAreRefusedNamingTheLine) {
  for (const char* bad : {"nan", "-nan", "NaN", "inf", "+Infinity", "nan(0x1)"}) {
    const std::string f = write("n.obj", std::string("v 0 0 0\nv 1 0 0\nv ") + bad + " " + bad + " 0\nf 1 2 3\n");
    const std::string e = refusal(f);
    EXPECT_NE(e.find("n.obj:3: non-finite number"), std::string::npos) << bad << ": " << e;
  }
  write("n.mtl", std::string("newmtl m\nKd nan 0 0\n"));
  const std::string e = refusal(write("m.obj", std::string("mtllib n.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")));
  EXPECT_NE(e.find("n.mtl:2: non-finite number"), std::string::npos) << e;
  const std::string ok = write("ok.obj", std::string("o nan\ng inf\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  EXPECT_EQ(fr::load_scene(ok).triangle_count(), 1u);
}

TEST_F(Hostile, EndlessOrHugeMaterialLibrariesAreBounded) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  // A device is not a material library: skipped with a warning, the geometry loads.
  const fr::Scene s = fr::load_scene(write("dev.obj", "mtllib /dev/zero\n" + tri));
  EXPECT_EQ(s.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(s, "material library \"/dev/zero\" missing"));
  // A library beyond the byte budget: refused naming it.
  write("big.mtl", "newmtl a\n" + std::string(3 << 20, '#'));
  fr::SceneLimits lim;
  lim.max_file_bytes = 1 << 20;
  const std::string e = refusal(write("big.obj", "mtllib big.mtl\n" + tri), lim);
  EXPECT_NE(e.find("big.obj: mtllib"), std::string::npos) << e;
  EXPECT_NE(e.find("big.mtl: larger than"), std::string::npos) << e;
  // Within the budget the library is used.
  write("red.mtl", std::string("newmtl red\nKd 1 0 0\n"));
  const fr::Scene r = fr::load_scene(write("red.obj", "mtllib red.mtl\nusemtl red\n" + tri));
  EXPECT_EQ(r.materials.back().base_color.x, 1.0f);
  EXPECT_EQ(r.materials.back().base_color.y, 0.0f);
}

// Every glTF and OBJ model of Debian's assimp-testmodels, including its deliberately
// malformed ones (IndexOutOfRange, MissingBin, RecursiveNodes, BoxWithInfinites, ...).
TEST(HostileCorpus, AssimpTestModelsLoadOrAreRefused) {
  const fs::path root = "/usr/share/assimp/models";
  ASSERT_TRUE(fs::is_directory(root)) << "install Debian's assimp-testmodels (./x deps)";
  int loaded = 0, refused = 0;
  for (const char* sub : {"glTF2", "OBJ", "invalid"})
    for (const auto& e : fs::recursive_directory_iterator(root / sub)) {
      const std::string ext = e.path().extension().string();
      if (ext != ".gltf" && ext != ".glb" && ext != ".obj") continue;
      try {
        const fr::Scene s = fr::load_scene(e.path().string());
        EXPECT_GT(s.triangle_count(), 0u);
        ++loaded;
      } catch (const fovea::core::InputError& err) {
        EXPECT_NE(std::string(err.what()).find(e.path().string()), std::string::npos) << err.what();
        ++refused;
      }
    }
  EXPECT_GT(loaded, 20);
  EXPECT_GT(refused, 3);
  std::printf("assimp-testmodels: %d loaded, %d refused\n", loaded, refused);
}
