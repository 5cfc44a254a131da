// Traversal throughput by ray type, as the path tracer casts them: primary rays from the eye,
// bounce rays (cosine-weighted from each primary hit) and shadow rays (from each primary hit
// to a point on an emitter, any-hit). Timed by GPU timestamps around the trace dispatches
// only (gpu::GpuTimer in Raycaster::trace), each batch repeated until the wall time outside
// them — submission, fence, reading the hits back — is under 5% of the whole; medians of 5
// batches. Both traversals (the compute BVH and, where the device offers them, ray queries)
// and, with Embree 3 installed, Embree on every CPU thread, on the same rays; ratios from this
// one run. Rays and their order are fixed (hash of the index), so every run traces the same.
//   fovea_bench_traversal [--scenes a,b,...] [--rays N]       (defaults: every built-in, 1M)
// (Google Benchmark's --benchmark_* options, which `./x bench` passes to every benchmark,
// are ignored.)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "fovea/core/display.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/renderer/path_tracer.hpp"
#include "fovea/renderer/raycaster.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "fovea/shaders/hash.h"
#include "fovea/shaders/pt_scene.h"

#ifdef FOVEA_HAVE_EMBREE
#include "embree_rays.hpp"
#endif

namespace fr = fovea::renderer;
namespace fc = fovea::core;
namespace fs = fovea::shaders;

namespace {

constexpr double kMaxOverhead = 0.05;  // wall time outside the dispatches, of the whole
constexpr int kBatches = 5;
constexpr float kEps = 1e-4f;  // ray offset off a surface, relative to the scene's size

struct RaySets {
  std::vector<fs::PtRay> primary, bounce, shadow;
};

fs::PtRay make_ray(glm::vec3 o, glm::vec3 d, float tmax) { return {o.x, o.y, o.z, 0.0f, d.x, d.y, d.z, tmax}; }

float unit(std::uint32_t i, std::uint32_t k) { return fs::hash_to_unit(fs::hash3(i, k, 0x7A3Bu)); }

// Primary rays through a Cartesian raster of the fove0 field with about `count` pixels, from
// the scene's camera; bounce and shadow rays from their hits.
RaySets make_rays(fovea::gpu::Context& ctx, const fr::Scene& scene, std::size_t count) {
  const fc::DisplayPreset fove0 = fc::load_display("fove0");
  const double scale = std::sqrt(double(count) / (double(fove0.width) * fove0.height));
  const fc::View view(fove0.fov(fc::Eye::Left), std::max(1, int(fove0.width * scale)),
                      std::max(1, int(fove0.height * scale)), scene.camera);
  RaySets r;
  const glm::dmat3 rot = glm::mat3_cast(view.pose().orientation);
  const glm::vec3 eye(view.pose().position);
  for (const auto& s : fr::cartesian_grid(view))
    r.primary.push_back(make_ray(eye, glm::vec3(glm::normalize(rot * glm::dvec3(s.dir_x, s.dir_y, s.dir_z))), 1e30f));

  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : scene.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const float eps = kEps * glm::length(hi - lo);
  std::vector<std::uint32_t> emitters;
  for (std::uint32_t t = 0; t < scene.triangle_count(); ++t)
    if (glm::length(scene.materials[scene.material[t]].emission) > 0) emitters.push_back(t);

  const fr::GpuScene g(ctx, scene, {}, fr::Tracing::Compute);
  fr::Raycaster rc(ctx, g);
  rc.set_rays(r.primary);
  const auto hits = rc.trace(fr::RayQuery::Closest);
  for (std::uint32_t i = 0; i < hits.size(); ++i) {
    if (hits[i].triangle == fs::kPtNoHit) continue;
    const fs::PtRay& pr = r.primary[i];
    const glm::vec3 d(pr.dir_x, pr.dir_y, pr.dir_z);
    const glm::vec3* v = &scene.positions[3 * std::size_t(hits[i].triangle)];
    glm::vec3 n = glm::normalize(glm::cross(v[1] - v[0], v[2] - v[0]));
    if (glm::dot(n, d) > 0) n = -n;
    const glm::vec3 p = eye + hits[i].t * d + eps * n;
    // Bounce: cosine-weighted about n.
    const float u1 = unit(i, 1), u2 = unit(i, 2), phi = 6.2831853f * u2, rr = std::sqrt(u1);
    const glm::vec3 a = std::abs(n.x) > 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 b1 = glm::normalize(glm::cross(a, n)), b2 = glm::cross(n, b1);
    r.bounce.push_back(make_ray(p, glm::normalize(rr * std::cos(phi) * b1 + rr * std::sin(phi) * b2 +
                                                  std::sqrt(std::max(0.0f, 1 - u1)) * n),
                                1e30f));
    // Shadow: to a uniform point of an emitter triangle, stopping short of it; without
    // emitters, towards the sky overhead.
    if (emitters.empty()) {
      r.shadow.push_back(make_ray(p, glm::vec3(0, 1, 0), 1e30f));
      continue;
    }
    const std::uint32_t e = emitters[std::min<std::size_t>(std::size_t(unit(i, 3) * float(emitters.size())),
                                                            emitters.size() - 1)];
    float s = unit(i, 4), t = unit(i, 5);
    if (s + t > 1) s = 1 - s, t = 1 - t;
    const glm::vec3* w = &scene.positions[3 * std::size_t(e)];
    const glm::vec3 q = w[0] + s * (w[1] - w[0]) + t * (w[2] - w[0]);
    const float dist = glm::length(q - p);
    if (dist > 2 * eps) r.shadow.push_back(make_ray(p, (q - p) / dist, dist - 2 * eps));
  }
  return r;
}

struct Rate {
  double rays_per_s = 0;  // median over the batches
  double overhead = 0;    // the wall time outside the dispatches, of the whole (median)
  int repeat = 0;
};

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// GPU rays per second of `rays` through `g`: dispatches repeated in one submission until
// what is not dispatch time is under kMaxOverhead of the wall time.
Rate gpu_rate(fovea::gpu::Context& ctx, const fr::GpuScene& g, const std::vector<fs::PtRay>& rays, bool any) {
  fr::Raycaster rc(ctx, g);
  rc.set_rays(rays);
  const fr::RayQuery q = any ? fr::RayQuery::Any : fr::RayQuery::Closest;
  rc.trace(q);  // warm-up: pipeline compilation, first touch of the buffers
  Rate out;
  for (int repeat = 1; repeat <= 64; repeat *= 2) {
    std::vector<double> rate, overhead;
    for (int b = 0; b < kBatches; ++b) {
      const auto t0 = std::chrono::steady_clock::now();
      rc.trace(q, repeat);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double gpu = double(rc.last_gpu_ns()) * 1e-9;
      if (gpu <= 0) return out;  // no timestamps on this queue
      rate.push_back(double(rays.size()) * repeat / gpu);
      overhead.push_back(std::max(0.0, 1 - gpu / wall));
    }
    out = {median(rate), median(overhead), repeat};
    if (out.overhead < kMaxOverhead) break;
  }
  return out;
}

#ifdef FOVEA_HAVE_EMBREE
double embree_rate(const fovea::bench::EmbreeScene& embree, const std::vector<fs::PtRay>& rays, bool any) {
  embree.trace(rays, any);
  std::vector<double> rate;
  for (int b = 0; b < kBatches; ++b) {
    const auto t0 = std::chrono::steady_clock::now();
    embree.trace(rays, any);
    rate.push_back(double(rays.size()) / std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return median(rate);
}
#endif

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> scenes = {"cornell", "furnace", "glossy-spheres", "stereo-occluders", "default"};
  std::size_t count = 1 << 20;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--scenes" && i + 1 < argc) {
      scenes = split(argv[++i]);
    } else if (a == "--rays" && i + 1 < argc) {
      count = std::size_t(std::max(1024.0, std::atof(argv[++i])));
    } else if (a.rfind("--benchmark_", 0) == 0) {
      continue;  // `./x bench` passes Google Benchmark's options to every benchmark
    } else {
      std::fprintf(stderr, "usage: fovea_bench_traversal [--scenes a,b,...] [--rays N]\n");
      return 2;
    }
  }
  fovea::gpu::Context ctx;
  const bool ray_query = ctx.features().ray_query;
  std::printf("device: %s (%s); GPU rays/s from timestamps around the dispatches; Embree: %s\n",
              ctx.info().name.c_str(), ctx.info().driver.c_str(),
#ifdef FOVEA_HAVE_EMBREE
              "all CPU threads, wall time"
#else
              "not built"
#endif
  );
  std::printf("%-17s %-8s %9s %13s %7s %13s %7s %11s %10s %10s\n", "scene", "rays", "count", "compute Mr/s", "over",
              "rayquery Mr/s", "over", "embree Mr/s", "rq/comp", "emb/comp");
  for (const std::string& name : scenes) {
    const fr::Scene scene = fr::load_scene(name);
    const RaySets sets = make_rays(ctx, scene, count);
    const fr::GpuScene compute(ctx, scene, {}, fr::Tracing::Compute);
    std::optional<fr::GpuScene> rq;
    if (ray_query) rq.emplace(ctx, scene, fr::BvhOptions{}, fr::Tracing::RayQuery);
#ifdef FOVEA_HAVE_EMBREE
    const fovea::bench::EmbreeScene embree(scene);
#endif
    const struct {
      const char* name;
      const std::vector<fs::PtRay>* rays;
      bool any;
    } kinds[] = {{"primary", &sets.primary, false}, {"bounce", &sets.bounce, false}, {"shadow", &sets.shadow, true}};
    for (const auto& k : kinds) {
      if (k.rays->empty()) continue;
      const Rate c = gpu_rate(ctx, compute, *k.rays, k.any);
      const Rate q = rq ? gpu_rate(ctx, *rq, *k.rays, k.any) : Rate{};
      double e = 0;
#ifdef FOVEA_HAVE_EMBREE
      e = embree_rate(embree, *k.rays, k.any);
#endif
      const auto ratio = [](double a, double b) { return b > 0 && a > 0 ? a / b : NAN; };
      std::printf("%-17s %-8s %9zu %13.2f %6.1f%% %13.2f %6.1f%% %11.2f %10.2f %10.2f\n", name.c_str(), k.name,
                  k.rays->size(), c.rays_per_s * 1e-6, 100 * c.overhead, q.rays_per_s * 1e-6, 100 * q.overhead,
                  e * 1e-6, ratio(q.rays_per_s, c.rays_per_s), ratio(e, c.rays_per_s));
      std::fflush(stdout);
    }
  }
  return 0;
}
