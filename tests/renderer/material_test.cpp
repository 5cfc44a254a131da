// Energy of the materials through the real shader on lavapipe: glTF doubleSided emission
// and shading (closed emissive sphere seen from inside), white-furnace bounds of the
// layered dielectric and of multiple-scattering-compensated rough metals.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <glm/geometric.hpp>

#include "fovea/renderer/procedural.hpp"
#include "gpu_fixture.hpp"
#include "pt_helpers.hpp"

namespace fr = fovea::renderer;
namespace fc = fovea::core;
using fovea::test::MeanSe;
using fovea::test::mean_se;
using fovea::test::trace_grid;

namespace {

// Closed sphere with outward normals (flat shading, so the enclosure balances exactly),
// Lambert albedo 0.5 and emission 1, seen from its centre.
fr::Scene inside_out_sphere(bool double_sided) {
  fr::Scene s;
  fr::Material m;
  m.base_color = glm::vec3(0.5f);
  m.specular = 0.0f;
  m.emission = glm::vec3(1.0f);
  m.double_sided = double_sided;
  fr::add_sphere(s, {0, 0, 0}, 1.0f, s.add_material(m), 12, 24, false);
  for (auto& n : s.normals) n = glm::vec3(0);
  fr::sanitize(s, "inside-out-sphere");
  return s;
}

struct Albedo {
  MeanSe normal, grazing;  // μ = cos θo in [0.9, 1] and [0.1, 0.3]
};

// A tessellated sphere under a uniform white sky (no emitters), one BSDF-sampled bounce:
// the radiance leaving a convex body towards the eye is its directional albedo E(μo),
// estimated by the shader's own sampling and evaluation.
Albedo sphere_albedo(fovea::gpu::Context& ctx, const fr::Material& m) {
  fr::Scene s;
  s.environment = glm::vec3(1.0f);
  const glm::vec3 centre(0, 0, -3);
  fr::add_sphere(s, centre, 1.0f, s.add_material(m), 64, 128);
  fr::sanitize(s, "albedo-sphere");
  fr::GpuScene g(ctx, s, {}, fovea::test::kStatisticsTracing);
  const fc::View v(fc::Fov::from_degrees(-20, 20, 20, -20), 32, 32);  // the sphere spans ±19.5°
  fr::PathConfig c;
  c.spp = 64;
  c.max_bounces = 1;
  const auto r = trace_grid(ctx, g, fr::cartesian_grid(v), v, fc::Eye::Left, c, 8);
  std::vector<double> normal, grazing;
  for (std::size_t i = 0; i < r.radiance.size(); ++i) {
    if (r.position_material[i].w < 0) continue;
    const glm::vec3 p(r.position_material[i]);
    const float mu = glm::dot(glm::normalize(p - centre), glm::normalize(-p));  // eye at the origin
    if (mu >= 0.9f) normal.push_back(r.radiance[i].x);
    if (mu >= 0.1f && mu <= 0.3f) grazing.push_back(r.radiance[i].x);
  }
  EXPECT_GE(normal.size(), 20u);
  EXPECT_GE(grazing.size(), 20u);
  return {mean_se(normal), mean_se(grazing)};
}

// Directional albedo E of `m` at each roughness, at normal and grazing incidence: E ≤ 1
// (+ 3 standard errors + 0.003 for the albedo table's interpolation) and E ≥ `lower`.
void expect_furnace_bounds(fovea::gpu::Context& ctx, const char* what, fr::Material m,
                           std::initializer_list<float> roughness, double lower) {
  for (const float rough : roughness) {
    m.roughness = rough;
    const Albedo a = sphere_albedo(ctx, m);
    std::printf("%s roughness %.2f: E(normal) = %.4f ± %.4f, E(grazing) = %.4f ± %.4f\n", what, rough,
                a.normal.mean, a.normal.se, a.grazing.mean, a.grazing.se);
    for (const MeanSe& e : {a.normal, a.grazing}) {
      EXPECT_LE(e.mean, 1.0 + 3.0 * e.se + 0.003) << what << " roughness " << rough;
      EXPECT_GE(e.mean, lower) << what << " roughness " << rough;
    }
  }
}

}  // namespace

class Materials : public fovea::test::GpuTest {};

// glTF 2.0 §3.9.5: back faces of double-sided materials are lit (and emit) with reversed
// normals. From inside a closed emissive Lambert sphere with outward normals, unlimited
// bounces: L = E / (1 − ρ) = 2. Unbiased (Russian roulette, the 256-bounce cap leaves
// 0.5²⁵⁶); 4096 paths per cell over 16 cells put 4 standard errors of the mean below the 1%
// tolerance (checked). Single-sided, the same sphere is black from inside.
TEST_F(Materials, DoubleSidedEmissiveSphereSeenFromInside) {
  const fc::View v(fc::Fov::from_degrees(-50, 50, 50, -50), 4, 4);
  fr::PathConfig c;
  c.spp = 256;
  c.max_bounces = -1;
  c.rr_start = 2;
  fr::GpuScene two(ctx(), inside_out_sphere(true));
  const auto r = trace_grid(ctx(), two, fr::cartesian_grid(v), v, fc::Eye::Left, c, 16);
  std::vector<double> cells;
  for (const auto& p : r.radiance) cells.push_back((p.x + p.y + p.z) / 3.0);
  const MeanSe m = mean_se(cells);
  std::printf("double-sided emissive sphere from inside: L = %.4f ± %.4f (analytic 2)\n", m.mean, m.se);
  EXPECT_NEAR(m.mean, 2.0, 0.02);
  EXPECT_LT(4.0 * m.se, 0.02);

  fr::GpuScene one(ctx(), inside_out_sphere(false));
  c.spp = 4;
  const auto b = trace_grid(ctx(), one, fr::cartesian_grid(v), v, fc::Eye::Left, c, 1);
  for (const auto& p : b.radiance) EXPECT_EQ(glm::vec3(p), glm::vec3(0.0f));
}

// White furnace of the layered dielectric (white base, F0 = 0.04): E(μo) ≤ 1 at normal and
// grazing incidence for every roughness (the unweighted Lambert + GGX sum gave 1.037 and 1.33
// at roughness 0.1). With the compensated layering the exact answer is 1; the lower bound
// shows the energy is kept, not dropped.
TEST_F(Materials, WhiteDielectricFurnaceStaysAtOrBelowOne) {
  fr::Material m;
  m.base_color = glm::vec3(1.0f);
  expect_furnace_bounds(ctx(), "white dielectric", m, {0.05f, 0.1f, 0.3f, 0.6f, 1.0f}, 0.95);
}

// Rough metals with the multiple-scattering lobe (Kulla & Conty 2017): a white metal (F0 = 1)
// reflects everything at every roughness and angle (single scattering alone lost up to 68%:
// E = 0.32 at normal incidence for roughness 1), and never more.
TEST_F(Materials, WhiteMetalKeepsItsEnergyAtEveryRoughness) {
  fr::Material m;
  m.base_color = glm::vec3(1.0f);
  m.metallic = 1.0f;
  expect_furnace_bounds(ctx(), "white metal", m, {0.05f, 0.3f, 0.5f, 0.7f, 1.0f}, 0.97);
}
