// BVH: structure on the CPU, and GPU traversal (closest and any hit) identical to brute
// force on random and adversarial geometry; watertightness of the triangle test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

#include "fovea/renderer/bvh.hpp"
#include "fovea/renderer/procedural.hpp"
#include "fovea/renderer/raycaster.hpp"
#include "gpu_fixture.hpp"

namespace fr = fovea::renderer;
using fovea::shaders::PtRay;

namespace {

std::vector<glm::vec3> random_soup(int n, float extent, float size, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<glm::vec3> p;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c(u(rng) * extent, u(rng) * extent, u(rng) * extent);
    for (int k = 0; k < 3; ++k) p.push_back(c + size * glm::vec3(u(rng), u(rng), u(rng)));
  }
  return p;
}

// A coplanar grid of quads in z = 0 (shared edges and vertices everywhere).
std::vector<glm::vec3> coplanar_grid(int n, float cell) {
  std::vector<glm::vec3> p;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const glm::vec3 a(i * cell, j * cell, 0), b((i + 1) * cell, j * cell, 0), c((i + 1) * cell, (j + 1) * cell, 0),
          d(i * cell, (j + 1) * cell, 0);
      p.insert(p.end(), {a, b, c, a, c, d});
    }
  return p;
}

// The box of slot k of a node as the shader decodes it (origin + q·2^e per plane).
struct Box {
  glm::vec3 lo, hi;
};
Box slot_box(const fovea::shaders::PtBvhNode& n, int k) {
  const float origin[3] = {n.origin_x, n.origin_y, n.origin_z};
  const std::uint32_t lo[3] = {n.lo_x, n.lo_y, n.lo_z}, hi[3] = {n.hi_x, n.hi_y, n.hi_z};
  Box b;
  for (int i = 0; i < 3; ++i) {
    const float step = std::ldexp(1.0f, int(std::int8_t(std::uint8_t(n.exponents >> (8 * i)))));
    b.lo[i] = origin[i] + float((lo[i] >> (8 * k)) & 0xFF) * step;
    b.hi[i] = origin[i] + float((hi[i] >> (8 * k)) & 0xFF) * step;
  }
  return b;
}
bool inside(const Box& b, glm::vec3 q) { return glm::all(glm::greaterThanEqual(q, b.lo)) && glm::all(glm::lessThanEqual(q, b.hi)); }

// sah_gain: the geometry is spread out, so the tree must beat a flat list clearly.
void check_structure(const std::vector<glm::vec3>& p, bool sah_gain = true, const fr::BvhOptions& options = {}) {
  const fr::Bvh b = fr::build_bvh(p, options);
  const std::size_t n = p.size() / 3;
  ASSERT_EQ(b.order.size(), n);
  std::vector<int> seen(n, 0);
  EXPECT_LE(b.depth, int(fovea::shaders::kPtBvhMaxDepth));
  // Walk the tree: every node reached once, every triangle inside the (decoded) boxes of
  // all slots on its path, as traversal needs.
  struct Item {
    std::size_t node;
    Box box;
  };
  const float big = std::numeric_limits<float>::max();
  std::vector<Item> stack{{0, {glm::vec3(-big), glm::vec3(big)}}};
  std::vector<int> reached(b.nodes.size(), 0);
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    ASSERT_LT(it.node, b.nodes.size());
    ++reached[it.node];
    const auto& node = b.nodes[it.node];
    for (int k = 0; k < 4; ++k) {
      if (node.child[k] == fovea::shaders::kPtNoHit) continue;
      const Box own = slot_box(node, k);
      const Box box{glm::max(own.lo, it.box.lo), glm::min(own.hi, it.box.hi)};
      const std::uint32_t count = (node.counts >> (8 * k)) & 0xFF;
      if (count > 0) {
        EXPECT_LE(node.child[k] + count, n);
        for (std::uint32_t i = node.child[k]; i < node.child[k] + count; ++i) {
          ++seen[b.order[i]];
          for (int v = 0; v < 3; ++v) EXPECT_TRUE(inside(box, p[3 * b.order[i] + v]));
        }
      } else {
        stack.push_back({node.child[k], box});
      }
    }
  }
  for (std::size_t i = 0; i < b.nodes.size(); ++i) ASSERT_EQ(reached[i], 1) << "node " << i;
  for (std::size_t t = 0; t < n; ++t) ASSERT_EQ(seen[t], 1) << "triangle " << t;
  if (sah_gain) {
    EXPECT_LT(b.sah_cost, 0.5 * double(n)) << "SAH cost no better than a flat list";
  }
}

// The furnace's closed sphere (inward faces), off the origin.
fr::Scene closed_sphere(glm::vec3 centre) {
  fr::Scene s;
  s.materials.push_back({});
  fr::add_sphere(s, centre, 1.0f, 0, 12, 24, true);
  s.camera.position = centre;
  return s;
}

}  // namespace

// From the centre of a closed sphere the SAH's halving tree keeps the eye inside a box at
// three levels (eight octants around it); the tree built for the eye's and the surfaces'
// rays takes cones around the eye and is kept because those rays do less work in it.
TEST(Bvh, RayGuidedTreeForAnEyeInsideAClosedSphere) {
  const glm::vec3 centre(0.1f, -0.2f, 0.3f);
  const fr::Scene s = closed_sphere(centre);
  fr::BvhOptions o;
  o.eye = centre;
  check_structure(s.positions, true, o);
  const fr::Bvh b = fr::build_bvh(s.positions, o);
  EXPECT_TRUE(b.ray_guided);
  EXPECT_LT(b.ray_cost, 0.9 * b.sah_ray_cost);
  const fr::Bvh again = fr::build_bvh(s.positions, o);  // deterministic
  EXPECT_EQ(again.order, b.order);
  EXPECT_DOUBLE_EQ(again.ray_cost, b.ray_cost);
  // Without an eye: the plain SAH tree, whose cost the guided build reported.
  fr::BvhOptions plain = o;
  plain.ray_samples = 0;
  const fr::Bvh sah = fr::build_bvh(s.positions, plain);
  EXPECT_FALSE(sah.ray_guided);
  EXPECT_NE(sah.order, b.order);
}

TEST(Bvh, RandomSoupIsAValidPartition) { check_structure(random_soup(5000, 10, 0.5f, 1)); }
TEST(Bvh, ParallelAndSerialBuildsAgree) {
  const auto p = random_soup(20000, 10, 0.3f, 2);
  fr::BvhOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const fr::Bvh a = fr::build_bvh(p, one), b = fr::build_bvh(p, two);
  EXPECT_EQ(a.order, b.order);
  EXPECT_EQ(a.nodes.size(), b.nodes.size());
  EXPECT_DOUBLE_EQ(a.sah_cost, b.sah_cost);
}
TEST(Bvh, CoincidentTrianglesStillSplit) {
  std::vector<glm::vec3> p;
  for (int i = 0; i < 1000; ++i) p.insert(p.end(), {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  check_structure(p, false);  // identical boxes: no split can reduce the SAH cost
  EXPECT_LE(fr::build_bvh(p).depth, 12);
}
TEST(Bvh, CoplanarHugeAndTinyGeometry) {
  check_structure(coplanar_grid(40, 1.0f));
  check_structure(random_soup(2000, 1e7f, 1e3f, 3));
  check_structure(random_soup(2000, 1e-3f, 1e-5f, 4));
  // Deep chain: triangles at exponentially shrinking scales force the depth limit.
  std::vector<glm::vec3> chain;
  for (int i = 0; i < 200; ++i) {
    const float s = std::ldexp(1.0f, -i / 2);
    chain.insert(chain.end(), {{s, 0, 0}, {s, s * 0.5f, 0}, {s, 0, s * 0.5f}});
  }
  check_structure(chain, false);
  // Slowly shrinking scales keep SAH splitting past its depth limit with many triangles
  // left: leaves beyond what a node can count are halved.
  std::vector<glm::vec3> slow;
  for (int i = 0; i < 3000; ++i) {
    const float s = std::pow(1.01f, -float(i));
    slow.insert(slow.end(), {{s, 0, 0}, {s, s * 0.5f, 0}, {s, 0, s * 0.5f}});
  }
  check_structure(slow, false);
}

class BvhGpu : public fovea::test::GpuTest {
 protected:
  // Closest and any hit through the BVH equal brute force for every ray.
  // sanitize = false keeps zero-area triangles (the loaders drop them, the BVH must not care).
  void expect_equal_to_brute_force(const std::vector<glm::vec3>& p, const std::vector<PtRay>& rays, bool sanitize = true) {
    fr::Scene s;
    s.materials.push_back({});
    for (std::size_t t = 0; t < p.size() / 3; ++t) s.add_triangle(p[3 * t], p[3 * t + 1], p[3 * t + 2], 0);
    if (sanitize) fr::sanitize(s, "test");
    fr::GpuScene g(ctx(), s, {}, fr::Tracing::Compute);  // the compute BVH under test
    fr::Raycaster rc(ctx(), g);
    rc.set_rays(rays);
    const auto bvh = rc.trace(fr::RayQuery::Closest), brute = rc.trace(fr::RayQuery::BruteClosest);
    const auto any = rc.trace(fr::RayQuery::Any), brute_any = rc.trace(fr::RayQuery::BruteAny);
    int hits = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(bvh[i].triangle == fovea::shaders::kPtNoHit, brute[i].triangle == fovea::shaders::kPtNoHit) << "ray " << i;
      ASSERT_EQ(bvh[i].t, brute[i].t) << "ray " << i;
      ASSERT_EQ(bvh[i].triangle, brute[i].triangle) << "ray " << i;  // equal distances: the lower index
      hits += bvh[i].triangle != fovea::shaders::kPtNoHit;
      ASSERT_EQ(any[i].triangle, brute_any[i].triangle) << "ray " << i;
      ASSERT_EQ(any[i].triangle == 0, bvh[i].triangle != fovea::shaders::kPtNoHit) << "ray " << i;
    }
    EXPECT_GT(hits, int(rays.size() / 20)) << "too few hits to test anything";
  }
};

namespace {

PtRay ray(glm::vec3 o, glm::vec3 d, float tmax = 1e30f) {
  d = glm::normalize(d);
  return {o.x, o.y, o.z, 0.0f, d.x, d.y, d.z, tmax};
}

// Random rays through the scene's bounds plus rays aimed exactly at vertices and edge
// midpoints and axis-parallel rays (zero direction components).
std::vector<PtRay> adversarial_rays(const std::vector<glm::vec3>& p, float extent, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<PtRay> r;
  for (int i = 0; i < 3000; ++i) {
    const glm::vec3 o(u(rng) * 2 * extent, u(rng) * 2 * extent, u(rng) * 2 * extent);
    const glm::vec3 target = p[std::size_t(rng() % p.size())];
    r.push_back(ray(o, glm::vec3(u(rng), u(rng), u(rng))));
    r.push_back(ray(o, target - o));
    const std::size_t t = 3 * (rng() % (p.size() / 3));
    r.push_back(ray(o, 0.5f * (p[t] + p[t + 1]) - o));
    const int axis = int(rng() % 3);
    glm::vec3 d(0);
    d[axis] = u(rng) < 0 ? -1.0f : 1.0f;
    r.push_back(ray(o, d, extent * (1 + u(rng))));
  }
  return r;
}

}  // namespace

TEST_F(BvhGpu, RandomSoupEqualsBruteForce) {
  const auto p = random_soup(3000, 10, 1.0f, 5);
  expect_equal_to_brute_force(p, adversarial_rays(p, 10, 6));
}

TEST_F(BvhGpu, CoplanarGridEqualsBruteForceIncludingGrazingRays) {
  const auto p = coplanar_grid(24, 1.0f);
  auto rays = adversarial_rays(p, 12, 7);
  for (int i = 0; i < 500; ++i) rays.push_back(ray({-1.0f, 0.37f * float(i % 60), 0.0f}, {1, 0.01f * float(i % 7), 0}));
  for (int i = 0; i < 500; ++i) rays.push_back(ray({float(i % 25), float(i / 25), 5.0f}, {0, 0, -1}));  // through vertices
  expect_equal_to_brute_force(p, rays);
}

TEST_F(BvhGpu, HugeAndTinyCoordinatesEqualBruteForce) {
  auto big = random_soup(1500, 1e7f, 2e5f, 8);
  expect_equal_to_brute_force(big, adversarial_rays(big, 1e7f, 9));
  auto tiny = random_soup(1500, 1e-3f, 1e-4f, 10);
  expect_equal_to_brute_force(tiny, adversarial_rays(tiny, 1e-3f, 11));
}

TEST_F(BvhGpu, RaysFromFarAwayEqualBruteForce) {
  // Origins 10⁴–10⁶ units from a scene of extent 10, aimed at vertices, edge midpoints and
  // random points of its bounds: box and triangle tests at large t.
  const auto p = random_soup(3000, 10, 1.0f, 12);
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<PtRay> rays;
  for (int i = 0; i < 6000; ++i) {
    const glm::vec3 away = glm::normalize(glm::vec3(u(rng), u(rng), u(rng))) * std::pow(10.0f, 4.0f + 2.0f * (0.5f + 0.5f * u(rng)));
    const std::size_t t = 3 * (rng() % (p.size() / 3));
    const glm::vec3 target = i % 3 == 0 ? p[t] : i % 3 == 1 ? 0.5f * (p[t] + p[t + 1]) : 10.0f * glm::vec3(u(rng), u(rng), u(rng));
    rays.push_back(ray(away, target - away));
  }
  expect_equal_to_brute_force(p, rays);
  // The same scene moved 10⁶ units from the world origin, rays from near it.
  std::vector<glm::vec3> moved = p;
  for (auto& v : moved) v += glm::vec3(1e6f, -2e6f, 5e5f);
  auto near = adversarial_rays(moved, 10, 14);
  for (auto& r : near) {
    r.org_x += 1e6f;
    r.org_y -= 2e6f;
    r.org_z += 5e5f;
  }
  expect_equal_to_brute_force(moved, near);
}

TEST_F(BvhGpu, DegenerateAndSliverTrianglesEqualBruteForce) {
  // Zero-area triangles (repeated vertices, collinear vertices), needles and slivers with
  // edges 10⁻⁶ of the others, mixed with ordinary ones.
  std::mt19937 rng(15);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<glm::vec3> p = random_soup(1000, 10, 1.0f, 16);
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 a(10 * u(rng), 10 * u(rng), 10 * u(rng)), d = glm::vec3(u(rng), u(rng), u(rng));
    const glm::vec3 e = glm::vec3(u(rng), u(rng), u(rng));
    switch (i % 4) {
      case 0: p.insert(p.end(), {a, a, a + d}); break;                    // repeated vertex
      case 1: p.insert(p.end(), {a, a + d, a + 2.0f * d}); break;         // collinear
      case 2: p.insert(p.end(), {a, a + d, a + d + 1e-6f * e}); break;    // needle
      default: p.insert(p.end(), {a, a + d, a + 0.5f * d + 1e-6f * e});   // sliver
    }
  }
  auto rays = adversarial_rays(p, 10, 17);
  expect_equal_to_brute_force(p, rays, false);
}

TEST_F(BvhGpu, DeepTreeEqualsBruteForce) {
  // Nested triangles at slowly shrinking scales make a deep tree (12 4-wide levels, over
  // twice the shipped scenes'), and the traversal stack is sized from the depth. The smallest
  // are 2.5·10⁻³ across: much smaller ones, seen from unit distance, fall below float
  // resolution and the triangle test (no double-precision fallback) reports false hits by
  // rounding, which brute force returns and the BVH's box test rightly culls.
  std::vector<glm::vec3> p;
  for (int i = 0; i < 3000; ++i) {
    const float s = std::pow(1.002f, -float(i));
    p.insert(p.end(), {{s, 0, 0}, {s, s * 0.5f, 0}, {s, 0, s * 0.5f}});
  }
  EXPECT_GE(fr::build_bvh(p).depth, 10);
  auto rays = adversarial_rays(p, 1.0f, 18);
  for (int i = 0; i < 2000; ++i) {  // along −x through the nested triangles
    const float y = 0.25f * std::pow(1.002f, -float(i)), z = 0.5f * y;
    rays.push_back(ray({2.0f, y, z}, {-1, 0, 0}));
  }
  expect_equal_to_brute_force(p, rays, false);
}

TEST_F(BvhGpu, TreeTooDeepForASharedStackEqualsBruteForce) {
  // The traversal keeps its stack in shared memory when the workgroup's stacks fit
  // (pt_traverse.h), else in a private array. Nested triangles halving in size every two
  // (2^60 down to 2^-14) make a tree of 23 4-wide levels: 69 entries for each of
  // pt_raycast's 64 invocations (35 KB), more than lavapipe's 32 KB, so this tree takes the
  // private stack there. Rays start near triangles of their own size (no rounding trouble,
  // DeepTreeEqualsBruteForce), and those from the origin hit the smallest, deepest one.
  std::vector<glm::vec3> p;
  for (int i = 0; i < 150; ++i) {
    const float s = std::ldexp(1.0f, 60 - i / 2);
    p.insert(p.end(), {{s, 0, 0}, {s, s * 0.5f, 0}, {s, 0, s * 0.5f}});
  }
  const int depth = fr::build_bvh(p).depth;
  EXPECT_GE(depth, 22);
  std::printf("%d 4-wide levels: %s stack on %s\n", depth,
              3u * std::uint32_t(depth) * 64u * 8u <= ctx().info().max_shared_memory_bytes ? "shared" : "private",
              ctx().info().name.c_str());
  std::vector<PtRay> rays;
  for (int i = 0; i < 150; ++i) {
    const float s = std::ldexp(1.0f, 60 - i / 2), y = 0.25f * s, z = 0.5f * y;
    rays.push_back(ray({0.0f, y, z}, {1, 0, 0}));           // the smallest triangle around it
    rays.push_back(ray({0.9f * s, y, z}, {-1, 0, 0}));      // the next smaller one
    rays.push_back(ray({0.0f, 0.0f, 0.0f}, {s, y, z}));     // its centre-ish from the origin
    rays.push_back(ray({0.5f * s, 0.1f * s, 0.1f * s}, {1, 0.2f, 0.1f}));
  }
  expect_equal_to_brute_force(p, rays, false);
}

TEST_F(BvhGpu, ClosedMeshIsWatertight) {
  // Rays from the centre of a closed sphere at its vertices and edge midpoints, where
  // non-watertight tests let rays slip between triangles, must all hit.
  fr::Scene s;
  s.materials.push_back({});
  fr::add_sphere(s, {0.1f, -0.2f, 0.3f}, 1.0f, 0, 40, 80);
  fr::sanitize(s, "sphere");
  std::vector<PtRay> rays;
  const glm::vec3 c(0.1f, -0.2f, 0.3f);
  for (std::size_t t = 0; t < s.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      rays.push_back(ray(c, s.positions[3 * t + k] - c));
      rays.push_back(ray(c, 0.5f * (s.positions[3 * t + k] + s.positions[3 * t + (k + 1) % 3]) - c));
    }
  fr::GpuScene g(ctx(), s, {}, fr::Tracing::Compute);
  fr::Raycaster rc(ctx(), g);
  rc.set_rays(rays);
  const auto hits = rc.trace(fr::RayQuery::Closest);
  int misses = 0;
  for (const auto& h : hits) misses += h.triangle == fovea::shaders::kPtNoHit;
  EXPECT_EQ(misses, 0) << "of " << hits.size();
}

// The ray-guided tree of the sphere around the eye: the same hits as the SAH tree, bit for
// bit, for rays from the eye (random directions, vertices, edge midpoints), with fewer
// node visits.
TEST_F(BvhGpu, RayGuidedTreeHitsAsTheSahTreeWithFewerNodeVisits) {
  const glm::vec3 c(0.1f, -0.2f, 0.3f);
  const fr::Scene s = closed_sphere(c);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<PtRay> rays;
  for (int i = 0; i < 4096; ++i) rays.push_back(ray(c, {u(rng), u(rng), u(rng)}));
  for (std::size_t t = 0; t < s.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      rays.push_back(ray(c, s.positions[3 * t + k] - c));
      rays.push_back(ray(c, 0.5f * (s.positions[3 * t + k] + s.positions[3 * t + (k + 1) % 3]) - c));
    }
  fr::BvhOptions plain;
  plain.ray_samples = 0;
  fr::GpuScene guided(ctx(), s, {}, fr::Tracing::Compute), sah(ctx(), s, plain, fr::Tracing::Compute);
  fr::Raycaster a(ctx(), guided), b(ctx(), sah);
  a.set_rays(rays);
  b.set_rays(rays);
  const auto ha = a.trace(fr::RayQuery::Closest), hb = b.trace(fr::RayQuery::Closest);
  const auto brute = a.trace(fr::RayQuery::BruteClosest);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    ASSERT_NE(ha[i].triangle, fovea::shaders::kPtNoHit) << "ray " << i;
    ASSERT_EQ(ha[i].t, hb[i].t) << "ray " << i;
    ASSERT_EQ(ha[i].t, brute[i].t) << "ray " << i;
    ASSERT_EQ(ha[i].triangle, brute[i].triangle) << "ray " << i;
    // At a shared vertex or edge the triangles tie and the lower index in the tree's
    // triangle order wins, which differs between trees; elsewhere the hit is the same.
    if (i >= 4096) continue;
    ASSERT_EQ(ha[i].triangle, hb[i].triangle) << "ray " << i;
    ASSERT_EQ(ha[i].u, hb[i].u) << "ray " << i;
    ASSERT_EQ(ha[i].v, hb[i].v) << "ray " << i;
  }
  fr::Raycaster ca(ctx(), guided, true), cb(ctx(), sah, true);
  ca.set_rays(rays);
  cb.set_rays(rays);
  const double na = ca.traversal_stats().nodes, nb = cb.traversal_stats().nodes;
  std::printf("sphere from its centre: %.2f node visits per ray (ray-guided tree), %.2f (SAH tree)\n", na, nb);
  EXPECT_LT(na, 0.75 * nb);
}

// The work counters of the benchmark (Raycaster count_traversal): two far-apart triangles
// make a root with two leaf slots, so a ray at one of them visits one node and tests one
// triangle, a ray past both visits the root only; every ray of a subgroup reports the
// most of its subgroup. Ray queries have no counters.
TEST_F(BvhGpu, TraversalCountersCountNodesAndTriangles) {
  fr::Scene s;
  s.materials.push_back({});
  s.add_triangle({-10, -1, -5}, {-8, -1, -5}, {-9, 1, -5}, 0);
  s.add_triangle({8, -1, -5}, {10, -1, -5}, {9, 1, -5}, 0);
  fr::GpuScene g(ctx(), s, {}, fr::Tracing::Compute);
  ASSERT_EQ(g.stats().nodes, 1u);
  fr::Raycaster rc(ctx(), g, true);
  std::vector<PtRay> rays;
  for (int i = 0; i < 64; ++i) rays.push_back(ray({i < 32 ? -9.0f : 0.0f, 0, 0}, {0, 0, -1}));
  rc.set_rays(rays);
  const fr::TraversalStats t = rc.traversal_stats();
  EXPECT_DOUBLE_EQ(t.nodes, 1.0);
  EXPECT_DOUBLE_EQ(t.triangles, 0.5);
  EXPECT_DOUBLE_EQ(t.subgroup_nodes, 1.0);
  EXPECT_GE(t.subgroup_triangles, t.triangles);
  EXPECT_THROW(fr::Raycaster(ctx(), g).traversal_stats(), std::logic_error);
  if (ctx().features().ray_query) {
    fr::GpuScene q(ctx(), s, {}, fr::Tracing::RayQuery);
    EXPECT_THROW(fr::Raycaster(ctx(), q, true), std::invalid_argument);
  }
}
