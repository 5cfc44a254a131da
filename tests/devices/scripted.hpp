#pragma once
// Scripted gaze for the devices tests: directions by angle, samples, a stream over a vector.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "fovea/devices/gaze.hpp"

namespace fovea::devices::test {

// The direction at azimuth `az` and elevation `el` (degrees, tangent-plane angles).
inline glm::dvec3 dir_deg(double az, double el = 0) {
  return glm::normalize(glm::dvec3(std::tan(az * M_PI / 180), std::tan(el * M_PI / 180), -1));
}

// A sample at t (all three times t) with the same gaze for both eyes and the combined gaze.
inline GazeSample sample(core::TimeNs t, glm::dvec3 d, std::uint32_t flags = kTracked) {
  GazeSample s;
  s.t_ns = s.device_time_ns = s.host_time_ns = t;
  s.combined.dir = d;
  s.combined.flags = flags;
  s.combined.confidence = flags == kTracked ? 1 : 0;
  s.left = s.right = s.combined;
  return s;
}

// A scripted stream; a live one delivers up to `limit_` samples (all by default).
class VectorStream final : public SampleStream {
 public:
  explicit VectorStream(std::vector<GazeSample> v, bool live = false) : v_(std::move(v)), live_(live) {}
  bool next(GazeSample& s) override {
    if (i_ >= std::min(v_.size(), limit_)) return false;
    s = v_[i_++];
    return true;
  }
  bool rewindable() const override { return !live_; }
  void rewind() override { i_ = 0; }
  bool live() const override { return live_; }
  std::string describe() const override { return "vector"; }
  std::size_t limit_ = SIZE_MAX;

 private:
  std::vector<GazeSample> v_;
  bool live_;
  std::size_t i_ = 0;
};

}  // namespace fovea::devices::test
