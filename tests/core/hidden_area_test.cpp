#include "fovea/core/hidden_area.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fovea/core/display.hpp"

using namespace fovea::core;

namespace {

// Coverage of the rendered view's pixel centres by a triangle list in tangent space.
std::vector<char> rasterise(const VisibilityMesh& m, const View& v) {
  const int W = v.width(), H = v.height();
  std::vector<char> out(size_t(W) * H, 0);
  const auto to_px = [&](glm::vec2 t) {
    return glm::dvec2((t.x - v.tan_left()) / (v.tan_right() - v.tan_left()) * W,
                      (v.tan_up() - t.y) / (v.tan_up() - v.tan_down()) * H);
  };
  for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
    const glm::dvec2 a = to_px(m.vertices[m.indices[i]]), b = to_px(m.vertices[m.indices[i + 1]]),
                     c = to_px(m.vertices[m.indices[i + 2]]);
    const int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x})))),
              x1 = std::min(W - 1, int(std::ceil(std::max({a.x, b.x, c.x})))),
              y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y})))),
              y1 = std::min(H - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
    const auto edge = [](glm::dvec2 p, glm::dvec2 q, glm::dvec2 r) {
      return (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
    };
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const glm::dvec2 p(x + 0.5, y + 0.5);
        // Pixel space has y down, so counter-clockwise tangent triangles are clockwise here.
        if (edge(a, b, p) <= 0 && edge(b, c, p) <= 0 && edge(c, a, p) <= 0) out[size_t(y) * W + x] = 1;
      }
  }
  return out;
}

double iou(const std::vector<char>& a, const std::vector<char>& b) {
  size_t inter = 0, uni = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    inter += a[i] && b[i];
    uni += a[i] || b[i];
  }
  return uni ? double(inter) / double(uni) : 1.0;
}

double signed_area(const VisibilityMesh& m) {
  double s = 0;
  for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
    const glm::dvec2 a = m.vertices[m.indices[i]], b = m.vertices[m.indices[i + 1]], c = m.vertices[m.indices[i + 2]];
    s += 0.5 * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
  }
  return s;
}

// Up 40°, down 50°, with the lens' optical axis at tangent 0 (display centre y = tan40/(tan40+tan50)).
DisplayPreset asymmetric() {
  return parse_display(
      R"({"name":"asym","width":200,"height":220,"fov_deg":{"left":-45,"right":45,"up":40,"down":-50},
          "lens":{"model":"panotools","k":[0.75,-0.01,0.75,0,3.8],"aberration":[0.999,1.008,1.018],
                  "centre":[0.5,0.41313],"scale":1.2,"cutoff":0.45}})",
      "asym");
}

void check_meshes(const DisplayPreset& d, Eye eye) {
  const HiddenAreaMask mask(Lens::for_eye(d, eye));
  const View& v = mask.lens().view();
  const int W = v.width(), H = v.height();
  std::vector<char> per_pixel(size_t(W) * H), per_pixel_hidden(size_t(W) * H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      per_pixel[size_t(y) * W + x] = mask.visible_view_px({x + 0.5, y + 0.5});
      per_pixel_hidden[size_t(y) * W + x] = !per_pixel[size_t(y) * W + x];
    }
  const VisibilityMesh vis = visibility_mesh(mask, VisibilityMeshType::VisibleTriangles);
  const VisibilityMesh hid = visibility_mesh(mask, VisibilityMeshType::HiddenTriangles);
  const VisibilityMesh loop = visibility_mesh(mask, VisibilityMeshType::LineLoop);
  EXPECT_EQ(vis.indices.size() % 3, 0u);
  EXPECT_EQ(hid.indices.size() % 3, 0u);
  EXPECT_GT(loop.indices.size(), 200u);
  size_t hidden_px = 0;
  for (char h : per_pixel_hidden) hidden_px += h;
  EXPECT_GT(double(hidden_px) / per_pixel_hidden.size(), 0.03) << d.name << ": the test needs a hidden area";
  const double iou_visible = iou(rasterise(vis, v), per_pixel), iou_hidden = iou(rasterise(hid, v), per_pixel_hidden);
  EXPECT_GE(iou_visible, 0.99) << d.name << " " << eye_name(eye);
  EXPECT_GE(iou_hidden, 0.99) << d.name << " " << eye_name(eye);
  ::testing::Test::RecordProperty(d.name + "_" + eye_name(eye) + "_iou", std::to_string(iou_visible) + " " + std::to_string(iou_hidden));
  // Counter-clockwise triangles (positive signed area) that tile the FOV rectangle.
  for (const auto* m : {&vis, &hid})
    for (size_t i = 0; i + 2 < m->indices.size(); i += 3) {
      VisibilityMesh one{m->vertices, {m->indices[i], m->indices[i + 1], m->indices[i + 2]}};
      ASSERT_GT(signed_area(one), 0);
    }
  const double rect = (v.tan_right() - v.tan_left()) * (v.tan_up() - v.tan_down());
  EXPECT_NEAR(signed_area(vis) + signed_area(hid), rect, 1e-5 * rect);
}

}  // namespace

TEST(HiddenArea, BitmaskMatchesTheOptics) {
  const DisplayPreset d = load_display("tiny");
  const Lens lens = Lens::for_eye(d, Eye::Left);
  const HiddenAreaMask mask(lens);
  size_t hidden = 0;
  for (int y = 0; y < d.height; ++y)
    for (int x = 0; x < d.width; ++x) {
      const LensSample s = lens.forward({(x + 0.5) / d.width, (y + 0.5) / d.height});
      bool outside = !s.within_lens;
      for (int c = 0; c < 3; ++c) {
        const glm::dvec2 uv = lens.tangent_to_uv(s.tangent[c]);
        outside = outside || uv.x < 0 || uv.y < 0 || uv.x > 1 || uv.y > 1;
      }
      EXPECT_EQ(mask.hidden(x, y), outside) << x << "," << y;
      hidden += outside;
    }
  EXPECT_DOUBLE_EQ(mask.hidden_fraction(), double(hidden) / (d.width * d.height));
  EXPECT_GT(mask.hidden_fraction(), 0.05);  // the corners at least
  EXPECT_LT(mask.hidden_fraction(), 0.4);
  EXPECT_TRUE(mask.hidden(0, 0));
  EXPECT_FALSE(mask.hidden(d.width / 2, d.height / 2));
  EXPECT_TRUE(mask.hidden_at({-1, 5}));
  EXPECT_EQ(mask.words_per_row(), 2);
}

TEST(HiddenArea, ViewDirections) {
  const HiddenAreaMask mask(Lens::for_eye(load_display("tiny"), Eye::Left));
  EXPECT_TRUE(mask.visible({0, 0, -1}));
  EXPECT_FALSE(mask.visible({0, 0, 1}));
  EXPECT_FALSE(mask.visible({std::nan(""), 0, -1}));
  EXPECT_FALSE(mask.visible({5, 0, -1}));                        // outside the FOV
  const View& v = mask.lens().view();
  EXPECT_FALSE(mask.visible({v.tan_left() * 0.999, v.tan_up() * 0.999, -1}));  // a corner
}

TEST(HiddenArea, MeshesMatchThePerPixelMask) {
  // Presets' optics at smaller rasters (the lenses are defined in panel fractions).
  const auto resized = [](const char* name, int w, int h) {
    DisplayPreset d = load_display(name);
    std::string text = d.json;
    const std::string ws = "\"width\": " + std::to_string(d.width), hs = "\"height\": " + std::to_string(d.height);
    text.replace(text.find(ws), ws.size(), "\"width\": " + std::to_string(w));
    text.replace(text.find(hs), hs.size(), "\"height\": " + std::to_string(h));
    d = parse_display(text, name);
    EXPECT_EQ(d.width, w);
    return d;
  };
  check_meshes(resized("fove0", 160, 180), Eye::Left);
  check_meshes(resized("vive", 180, 200), Eye::Right);
}

TEST(HiddenArea, MeshesMatchWithAsymmetricFov) {
  const DisplayPreset d = asymmetric();
  check_meshes(d, Eye::Left);
  // The mesh is not mirrored about y = 0: it reaches further down (50°) than up (40°).
  const HiddenAreaMask mask(Lens::for_eye(d, Eye::Left));
  const VisibilityMesh loop = visibility_mesh(mask, VisibilityMeshType::LineLoop);
  float ymin = 1e9f, ymax = -1e9f;
  for (const auto& p : loop.vertices) {
    ymin = std::min(ymin, p.y);
    ymax = std::max(ymax, p.y);
  }
  EXPECT_GE(ymin, std::tan(-50 * M_PI / 180) - 1e-6);
  EXPECT_LE(ymax, std::tan(40 * M_PI / 180) + 1e-6);
  EXPECT_GT(-ymin, ymax + 0.2);
}
