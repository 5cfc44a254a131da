#pragma once
// Embree 3 as a benchmark-only comparator: one scene's triangles in an Embree scene, and a
// batch of PtRays traced on every hardware thread (closest hit or occlusion). Only built
// where Embree is installed (FOVEA_HAVE_EMBREE); never linked into the project's libraries.
#include <embree3/rtcore.h>

#include <algorithm>
#include <span>
#include <thread>
#include <vector>

#include "fovea/renderer/scene.hpp"
#include "fovea/shaders/pt_raycast.h"

namespace fovea::bench {

class EmbreeScene {
 public:
  explicit EmbreeScene(const renderer::Scene& s) : dev_(rtcNewDevice(nullptr)), scene_(rtcNewScene(dev_)) {
    RTCGeometry geom = rtcNewGeometry(dev_, RTC_GEOMETRY_TYPE_TRIANGLE);
    const std::size_t n = s.triangle_count();
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
    auto* idx = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n));
    for (std::size_t i = 0; i < 3 * n; ++i) {
      v[3 * i] = s.positions[i].x;
      v[3 * i + 1] = s.positions[i].y;
      v[3 * i + 2] = s.positions[i].z;
      idx[i] = unsigned(i);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene_);
  }
  ~EmbreeScene() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(dev_);
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Traces every ray (closest hit, or occlusion when `any`), rays interleaved over threads.
  void trace(std::span<const shaders::PtRay> rays, bool any) const {
    const unsigned threads = std::max(1u, std::thread::hardware_concurrency());
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t)
      pool.emplace_back([&, t] {
        RTCIntersectContext ictx;
        rtcInitIntersectContext(&ictx);
        unsigned sink = 0;
        for (std::size_t i = t; i < rays.size(); i += threads) {
          const shaders::PtRay& r = rays[i];
          RTCRayHit rh{};
          rh.ray.org_x = r.org_x, rh.ray.org_y = r.org_y, rh.ray.org_z = r.org_z;
          rh.ray.dir_x = r.dir_x, rh.ray.dir_y = r.dir_y, rh.ray.dir_z = r.dir_z;
          rh.ray.tnear = r.tmin;
          rh.ray.tfar = r.tmax;
          rh.ray.mask = ~0u;
          rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
          if (any) {
            rtcOccluded1(scene_, &ictx, &rh.ray);
            sink += rh.ray.tfar < 0 ? 1u : 0u;
          } else {
            rtcIntersect1(scene_, &ictx, &rh);
            sink += rh.hit.primID;
          }
        }
        volatile unsigned keep = sink;  // the results are used
        (void)keep;
      });
    for (auto& th : pool) th.join();
  }

 private:
  RTCDevice dev_;
  RTCScene scene_;
};

}  // namespace fovea::bench
