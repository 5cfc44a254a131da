#include "gaze.hpp"

#include <cmath>
#include <algorithm>
#include <cstdint>
#include <cstdlib>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/trigonometric.hpp>

#include "fovea/core/error.hpp"

namespace fovea::runtime {
namespace {

// A fixation/saccade/blink script: fixations of 300 ms on targets within ±15° (chosen by a
// seeded hash of the fixation index), 40 ms saccades between them, a 150 ms blink every 4 s.
// The tracker runs at 120 Hz: a query returns the last sample on that grid.
class SyntheticGaze final : public GazeTracker {
 public:
  explicit SyntheticGaze(std::uint64_t seed) : seed_(seed) {}

  GazeSample sample_at(core::TimeNs t_ns, core::TimeNs epoch_ns) override {
    const core::TimeNs rel = std::max<core::TimeNs>(0, t_ns - epoch_ns);
    const core::TimeNs k = rel / kSamplePeriod;
    GazeSample s;
    s.sample_ns = epoch_ns + k * kSamplePeriod;
    const core::TimeNs ts = k * kSamplePeriod;
    s.valid = (ts % kBlinkEvery) < kBlinkEvery - kBlinkLength;  // blink at the end of each cycle
    const std::int64_t fix = ts / kFixationCycle;
    const core::TimeNs in_cycle = ts % kFixationCycle;
    const glm::dvec2 to = target(fix);
    glm::dvec2 ang = to;
    if (in_cycle < kSaccade) {
      const double u = double(in_cycle) / double(kSaccade);
      const double smooth = u * u * (3 - 2 * u);
      ang = glm::mix(target(fix - 1), to, smooth);
    }
    // Yaw/pitch (radians) -> view-space direction, -Z forward.
    s.dir = glm::normalize(glm::dvec3(std::sin(ang.x) * std::cos(ang.y), std::sin(ang.y),
                                      -std::cos(ang.x) * std::cos(ang.y)));
    return s;
  }

  std::string describe() const override { return "synthetic:" + std::to_string(seed_); }

 private:
  static constexpr core::TimeNs kSamplePeriod = 1'000'000'000 / 120;
  static constexpr core::TimeNs kFixationCycle = core::ms_to_ns(340);
  static constexpr core::TimeNs kSaccade = core::ms_to_ns(40);
  static constexpr core::TimeNs kBlinkEvery = core::ms_to_ns(4000);
  static constexpr core::TimeNs kBlinkLength = core::ms_to_ns(150);

  glm::dvec2 target(std::int64_t i) const {
    if (i < 0) return {0, 0};
    std::uint64_t h = seed_ * 0x9E3779B97F4A7C15ull + std::uint64_t(i) * 0xBF58476D1CE4E5B9ull;
    h ^= h >> 31;
    h *= 0x94D049BB133111EBull;
    h ^= h >> 29;
    const double u = double(h & 0xFFFFFF) / double(0xFFFFFF);
    const double v = double((h >> 24) & 0xFFFFFF) / double(0xFFFFFF);
    return {glm::radians(30.0 * u - 15.0), glm::radians(30.0 * v - 15.0)};
  }

  std::uint64_t seed_;
};

}  // namespace

std::unique_ptr<GazeTracker> open_gaze_tracker(const std::string& spec) {
  if (spec.empty() || spec == "synthetic") return std::make_unique<SyntheticGaze>(1);
  if (spec.rfind("synthetic:", 0) == 0) {
    const std::string n = spec.substr(10);
    char* end = nullptr;
    const unsigned long long seed = std::strtoull(n.c_str(), &end, 10);
    if (n.empty() || *end != '\0') throw core::InputError("FOVEA_GAZE=" + spec + ": seed must be an unsigned integer");
    return std::make_unique<SyntheticGaze>(seed);
  }
  throw core::InputError("FOVEA_GAZE=" + spec + ": unknown gaze source (expected synthetic[:seed])");
}

}  // namespace fovea::runtime
