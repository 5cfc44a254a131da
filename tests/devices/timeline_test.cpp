#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/devices/timeline.hpp"
#include "test_util.hpp"

using namespace fovea::devices;
using fovea::core::TimeNs;

namespace {
// A recording whose combined gaze sweeps 0.1 rad/s... encoded as x = t in seconds at z=-1.
class RampStream final : public SampleStream {
 public:
  RampStream(int n, TimeNs dt, TimeNs gap_at = -1, TimeNs gap = 0) : n_(n), dt_(dt), gap_at_(gap_at), gap_(gap) {}
  bool next(GazeSample& s) override {
    if (i_ >= n_) return false;
    s = GazeSample{};
    s.t_ns = i_ * dt_ + (gap_at_ >= 0 && i_ >= gap_at_ ? gap_ : 0);
    s.device_time_ns = s.t_ns + 5'000'000'000;
    s.host_time_ns = s.t_ns;
    s.combined.dir = glm::normalize(glm::dvec3(static_cast<double>(s.t_ns) * 1e-9, 0, -1));
    s.combined.flags = kTracked;
    s.combined.confidence = 1;
    s.left = s.right = s.combined;
    ++i_;
    ++pulled;
    return true;
  }
  bool rewindable() const override { return true; }
  void rewind() override {
    i_ = 0;
    ++rewinds;
  }
  std::string describe() const override { return "ramp"; }
  int pulled = 0, rewinds = 0;

 private:
  int n_;
  TimeNs dt_, gap_at_, gap_;
  int i_ = 0;
};

double x_at(GazeSource& s, TimeNs t) {
  const GazeSample g = s.sample_at(t);
  return g.combined.dir.x / -g.combined.dir.z;
}
}  // namespace

TEST(Timeline, NewestSampleAtOrBeforeTheQueryWithItsOwnTime) {
  SourceOptions o;
  o.horizon_ns = 0;  // no prediction: the newest sample as measured
  TimelineSource src(std::make_unique<RampStream>(11, 10'000'000), o);  // 0..100 ms
  EXPECT_NEAR(x_at(src, 0), 0.0, 1e-12);
  EXPECT_NEAR(x_at(src, 15'000'000), 0.010, 1e-12);  // between samples 1 and 2: sample 1
  EXPECT_NEAR(x_at(src, 42'500'000), 0.040, 1e-12);
  EXPECT_NEAR(x_at(src, 500'000'000), 0.1, 1e-12);  // after the last: clamped, not extrapolated
  const GazeSample g = src.sample_at(15'000'000);
  EXPECT_EQ(g.t_ns, 10'000'000);  // when it was measured, not the query time
  EXPECT_EQ(g.device_time_ns, 5'010'000'000);
  EXPECT_TRUE(g.tracked());
  EXPECT_EQ(src.sample_at(500'000'000).t_ns, 100'000'000);
  const GazeSample before = src.sample_at(-5'000'000);  // nothing measured yet
  EXPECT_EQ(before.t_ns, kNoSample);
  EXPECT_FALSE(before.tracked());
}

TEST(Timeline, AStaleNewestSampleIsLost) {
  SourceOptions o;
  o.max_gap_ns = 50'000'000;
  TimelineSource src(std::make_unique<RampStream>(10, 10'000'000, 5, 200'000'000), o);
  // Samples at 0..40 ms, then 250..290 ms.
  EXPECT_TRUE(src.sample_at(35'000'000).tracked());
  const GazeSample mid = src.sample_at(100'000'000);
  EXPECT_FALSE(mid.tracked());
  EXPECT_EQ(mid.combined.flags, kLost);
  EXPECT_EQ(mid.t_ns, 40'000'000);  // the newest sample there was
  EXPECT_TRUE(src.sample_at(260'000'000).tracked());
}

TEST(Timeline, SpeedLoopAndBackwardSeekWithBoundedWindow) {
  SourceOptions o;
  o.window_ns = 100'000'000;
  o.speed = 2.0;
  o.loop = true;
  auto stream = std::make_unique<RampStream>(1000, 1'000'000);  // 0..999 ms
  RampStream* raw = stream.get();
  TimelineSource src(std::move(stream), o);
  EXPECT_NEAR(x_at(src, 100'000'000), 0.2, 1e-9);  // 2x speed
  EXPECT_NEAR(x_at(src, 450'000'000), 0.9, 1e-9);
  EXPECT_LE(src.window_size(), 102u);  // bounded history
  EXPECT_NEAR(x_at(src, 50'000'000), 0.1, 1e-9);  // before the window: re-read from the start
  EXPECT_EQ(raw->rewinds, 1);
  // Loop: the recording is 1000 ms long (last sample + one period) -> t' = 2·t mod 1 s.
  EXPECT_NEAR(x_at(src, 700'000'000), 0.4, 1e-9);
}

TEST(Timeline, OpenReplayAndSyntheticByUri) {
  SourceOptions o;
  auto syn = open_gaze_source("synthetic:5?task=reading&rate=250", o);
  const GazeSample a = syn->sample_at(1'000'000'000), b = syn->sample_at(1'000'000'000);
  EXPECT_EQ(a.combined.dir, b.combined.dir);  // deterministic
  EXPECT_NEAR(glm::length(a.combined.dir), 1.0, 1e-9);
  EXPECT_LT(a.combined.dir.z, 0);
  const std::string def = fovea::devices::test::source_dir() + "/data/gaze/default.csv";
  auto rep = open_gaze_source("replay:" + def + "?speed=1&loop=1", o);
  EXPECT_TRUE(rep->sample_at(0).tracked() || !rep->sample_at(0).tracked());
  EXPECT_EQ(rep->sample_at(0).t_ns, 0);
  auto plain = open_gaze_source(def, o);  // a plain path is a replay
  EXPECT_EQ(plain->sample_at(2'000'000'000).combined.dir, rep->sample_at(2'000'000'000).combined.dir);
  EXPECT_THROW(open_gaze_source("synthetic:abc", o), fovea::core::InputError);
  EXPECT_THROW(open_gaze_source("synthetic:1?tsk=reading", o), fovea::core::InputError);
  EXPECT_THROW(open_gaze_source("synthetic:1?rate=5000", o), fovea::core::InputError);
  EXPECT_THROW(open_gaze_source("replay:" + def + "?speed=fast", o), fovea::core::InputError);
  EXPECT_THROW(open_gaze_source("mouse", o), fovea::core::InputError);
}
