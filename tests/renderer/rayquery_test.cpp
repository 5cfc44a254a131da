// Ray-query tracing (VK_KHR_ray_query through the scene's acceleration structure) against
// the compute BVH traversal on every built-in scene: the same primary hits, the same
// shadow-query answers and, with the same seeds, the same converged images; the fallback
// to the compute path on a device without ray queries, and the CLI's refusal there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include "fovea/core/error.hpp"
#include "fovea/gpu/accel.hpp"
#include "fovea/renderer/procedural.hpp"
#include "fovea/renderer/raycaster.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pt_helpers.hpp"

namespace fr = fovea::renderer;
namespace fc = fovea::core;
using fovea::shaders::kPtNoHit;
using fovea::shaders::PtHitRecord;
using fovea::shaders::PtRay;

namespace {

class RayQuery : public fovea::test::GpuTest {
 protected:
  void SetUp() override {
    GpuTest::SetUp();
    if (!ctx().features().ray_query)
      GTEST_SKIP() << "the Vulkan device '" << ctx().info().name << "' (" << ctx().info().driver
                   << ") offers no ray queries (VK_KHR_acceleration_structure + VK_KHR_ray_query), e.g. Mesa 22.3 "
                      "lavapipe; only the compute traversal runs there";
  }
};

fc::View scene_view(const fr::Scene& s, int size) {
  return fc::View(fc::Fov::from_degrees(-45, 45, 45, -45), size, size, s.camera);
}

// One ray per pixel centre of `view`, from the eye, in world space.
std::vector<PtRay> primary_rays(const fc::View& view) {
  const glm::dmat3 rot = glm::mat3_cast(view.pose().orientation);
  const glm::dvec3 o = view.pose().position;
  std::vector<PtRay> rays;
  for (int y = 0; y < view.height(); ++y)
    for (int x = 0; x < view.width(); ++x) {
      const glm::dvec3 d = glm::normalize(rot * view.pixel_to_dir({x + 0.5, y + 0.5}));
      rays.push_back({float(o.x), float(o.y), float(o.z), 0.0f, float(d.x), float(d.y), float(d.z), 1e30f});
    }
  return rays;
}

// Distance of a hit from its triangle's nearest edge, in barycentric units.
float on_edge(const PtHitRecord& h) { return std::min({h.u, h.v, 1.0f - h.u - h.v}); }

std::vector<PtHitRecord> trace(fovea::gpu::Context& ctx, const fr::GpuScene& g, const std::vector<PtRay>& rays,
                               fr::RayQuery q) {
  fr::Raycaster rc(ctx, g);
  rc.set_rays(rays);
  return rc.trace(q);
}

}  // namespace

TEST_F(RayQuery, PrimaryHitsAndShadowQueriesMatchTheComputeTraversal) {
  for (const std::string& name : fr::builtin_scene_names()) {
    SCOPED_TRACE(name);
    const fr::Scene s = fr::load_scene(name);
    const fr::GpuScene compute(ctx(), s, {}, fr::Tracing::Compute), rq(ctx(), s, {}, fr::Tracing::RayQuery);
    ASSERT_EQ(compute.tracing(), fr::Tracing::Compute);
    ASSERT_EQ(rq.tracing(), fr::Tracing::RayQuery);
    EXPECT_GT(rq.stats().accel_bytes, 0u);
    std::vector<PtRay> rays = primary_rays(scene_view(s, 64));
    const auto a = trace(ctx(), compute, rays, fr::RayQuery::Closest), b = trace(ctx(), rq, rays, fr::RayQuery::Closest);
    int hits = 0, ties = 0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(a[i].triangle == kPtNoHit, b[i].triangle == kPtNoHit) << "ray " << i;
      if (a[i].triangle == kPtNoHit) continue;
      ++hits;
      ASSERT_NEAR(b[i].t, a[i].t, 1e-4 * a[i].t) << "ray " << i;
      if (a[i].triangle != b[i].triangle) {
        // A ray through an edge shared by two triangles hits both at the same distance;
        // which one is reported is up to the implementation.
        ASSERT_LT(on_edge(a[i]), 1e-4f) << "ray " << i << ": triangle " << a[i].triangle << " vs " << b[i].triangle;
        ASSERT_LT(on_edge(b[i]), 1e-4f) << "ray " << i << ": triangle " << a[i].triangle << " vs " << b[i].triangle;
        ++ties;
        continue;
      }
      ASSERT_NEAR(b[i].u, a[i].u, 1e-3) << "ray " << i;
      ASSERT_NEAR(b[i].v, a[i].v, 1e-3) << "ray " << i;
    }
    EXPECT_LE(ties, int(rays.size() / 500)) << "edge ties";
    EXPECT_GT(hits, int(rays.size() / 4)) << "too few hits to compare";

    // Shadow queries (any hit): each primary ray shortened to just before and just past
    // its closest hit; occluded exactly when it reaches the surface.
    std::vector<PtRay> shadow;
    std::vector<bool> reaches;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      if (a[i].triangle == kPtNoHit) continue;
      for (float f : {0.999f, 1.001f}) {
        PtRay r = rays[i];
        r.tmax = a[i].t * f;
        shadow.push_back(r);
        reaches.push_back(f > 1.0f);
      }
    }
    const auto sa = trace(ctx(), compute, shadow, fr::RayQuery::Any), sb = trace(ctx(), rq, shadow, fr::RayQuery::Any);
    for (std::size_t i = 0; i < shadow.size(); ++i) {
      ASSERT_EQ(sa[i].triangle, sb[i].triangle) << "shadow ray " << i;
      ASSERT_EQ(sb[i].triangle == 0, bool(reaches[i])) << "shadow ray " << i;
    }
  }
}

TEST_F(RayQuery, ConvergedMeansMatchTheComputeTraversal) {
  fr::PathConfig config;
  config.spp = 8;
  config.jitter = true;
  const std::uint32_t frames = 16;  // 128 samples per pixel
  for (const std::string& name : fr::builtin_scene_names()) {
    SCOPED_TRACE(name);
    const fr::Scene s = fr::load_scene(name);
    const fr::GpuScene compute(ctx(), s, {}, fr::Tracing::Compute), rq(ctx(), s, {}, fr::Tracing::RayQuery);
    const fc::View view = scene_view(s, 16);
    const auto grid = fr::cartesian_grid(view);
    const auto a = fovea::test::trace_grid(ctx(), compute, grid, view, fc::Eye::Left, config, frames);
    const auto b = fovea::test::trace_grid(ctx(), rq, grid, view, fc::Eye::Left, config, frames);
    const glm::dvec3 ma = fovea::test::mean_rgb(a.radiance), mb = fovea::test::mean_rgb(b.radiance);
    for (int c = 0; c < 3; ++c) {
      ASSERT_GT(ma[c], 0.0) << "channel " << c << ": a black image compares nothing";
      EXPECT_NEAR(mb[c] / ma[c], 1.0, 0.005) << "channel " << c;
    }
    // First-hit features come from the primary rays, which hit the same surfaces.
    for (std::size_t i = 0; i < grid.size(); ++i) {
      const glm::vec4 pa = a.position_material[i], pb = b.position_material[i];
      ASSERT_EQ(pa.w, pb.w) << "material of cell " << i;
      ASSERT_LE(glm::distance(glm::vec3(pa), glm::vec3(pb)), 1e-4f * (1.0f + glm::length(glm::vec3(pa)))) << "cell " << i;
    }
  }
}

TEST_F(RayQuery, AccelerationStructureInputIsChecked) {
  const std::vector<float> one = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const fovea::gpu::TriangleAccel accel(ctx(), one);
  EXPECT_GT(accel.bytes(), 0u);
  EXPECT_THROW(fovea::gpu::TriangleAccel(ctx(), std::vector<float>(one.begin(), one.end() - 1)), fc::InputError);
  EXPECT_THROW(fovea::gpu::TriangleAccel(ctx(), std::vector<float>{}), fc::InputError);
  // An acceleration structure only goes where the layout declares one.
  const fovea::gpu::DescriptorSetLayout layout(ctx(), {fovea::gpu::Binding::StorageBuffer});
  fovea::gpu::DescriptorSet set(ctx(), layout);
  EXPECT_THROW(set.bind(0, accel), fc::InputError);
}

// A device without ray queries, simulated by leaving them off: auto falls back to the
// compute traversal, which renders; rayquery is refused with the reason.
TEST(RayQueryFallback, AutoUsesTheComputeTraversalAndRayQueryIsRefused) {
  fovea::gpu::ContextOptions o;
  o.validation = true;
  o.ray_query = false;
  fovea::gpu::Context ctx(o);
  ASSERT_FALSE(ctx.features().ray_query);
  const fr::Scene s = fr::make_cornell();
  const fr::GpuScene g(ctx, s);
  EXPECT_EQ(g.tracing(), fr::Tracing::Compute);
  EXPECT_EQ(g.stats().accel_bytes, 0u);
  const fc::View view = scene_view(s, 8);
  const auto t = fovea::test::trace_grid(ctx, g, fr::cartesian_grid(view), view, fc::Eye::Left, {});
  EXPECT_GT(fovea::test::mean_rgb(t.radiance).x, 0.0);
  EXPECT_THROW(fovea::gpu::TriangleAccel(ctx, std::vector<float>(9, 0.0f)), fc::InputError);
  try {
    const fr::GpuScene refused(ctx, s, {}, fr::Tracing::RayQuery);
    ADD_FAILURE() << "rayquery accepted on a context without ray queries";
  } catch (const fc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("does not offer ray queries"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ctx.validation_errors(), 0);
}

#ifdef FOVEA_EXE  // the fovea program is built
TEST(RayQueryCli, TraceOptionIsCheckedAndRayQueryWithoutTheExtensionExitsWithTwo) {
  const std::string fovea = FOVEA_EXE;
  const auto dir = std::filesystem::temp_directory_path() / ("fovea_rqcli_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string out = (dir / "x.exr").string();
  auto status = [&](const std::string& env, const std::string& args) {
    const std::string cmd = env + " " + fovea + " reference --display tiny --spp 1 --scene cornell --out " + out + " " +
                            args + " >" + (dir / "log").string() + " 2>&1";
    const int rc = std::system(cmd.c_str());
    return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  };
  EXPECT_EQ(status("", "--trace bvh"), 2);
  EXPECT_EQ(status("", "--trace compute"), 0);
  // Mesa 22.3 lavapipe, Debian 12's system driver, offers no ray queries.
  const std::string mesa22 = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";
  if (std::filesystem::exists(mesa22)) {
    std::filesystem::remove(out);
    EXPECT_EQ(status("VK_ICD_FILENAMES=" + mesa22, "--trace rayquery"), 2);
    EXPECT_FALSE(std::filesystem::exists(out));
    std::ifstream log(dir / "log");
    const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("does not offer ray queries"), std::string::npos) << text;
    EXPECT_EQ(status("VK_ICD_FILENAMES=" + mesa22, "--trace auto"), 0);
  }
  std::filesystem::remove_all(dir);
}
#endif
