// The foveation gaze: time base (live vs recorded), true sample times at any query time and
// rate with and without prediction, the loss policy with known answers, and a HID capture
// replayed as a recording.
#include <cmath>
#include <random>
#include <set>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/devices/foveation_gaze.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "fovea/devices/timeline.hpp"
#include "scripted.hpp"
#include "test_util.hpp"

using namespace fovea::devices;
using namespace fovea::devices::test;
using fovea::core::angle_deg;
using fovea::core::TimeNs;

namespace {
double az_deg(const glm::dvec3& d) { return std::atan2(d.x, -d.z) * 180 / M_PI; }

// A sample with a tracker clock of its own, received 2 ms after it was measured.
GazeSample stamped(TimeNs t, glm::dvec3 d) {
  GazeSample s = sample(t, d);
  s.device_time_ns = t + 123'456'789;
  s.host_time_ns = t + 2'000'000;
  return s;
}

FoveationGaze make(std::vector<GazeSample> v, bool live, TimeNs horizon_ns, const LossPolicy& policy = {}) {
  SourceOptions o;
  o.horizon_ns = horizon_ns;
  return FoveationGaze(std::make_unique<TimelineSource>(std::make_unique<VectorStream>(std::move(v), live), o), policy);
}

// Smooth pursuit at 10 °/s starting at `t0`, sampled at `rate_hz`, for one second.
std::vector<GazeSample> pursuit(double rate_hz, TimeNs t0) {
  std::vector<GazeSample> v;
  for (int i = 0; i < int(rate_hz); ++i) {
    const TimeNs t = t0 + std::llround(i * 1e9 / rate_hz);
    v.push_back(stamped(t, dir_deg(-5 + 10.0 * double(t - t0) * 1e-9)));
  }
  return v;
}
}  // namespace

TEST(FoveationGaze, RecordedSourcesStartAtTheEpoch) {
  const TimeNs epoch = 7'000'000'000'000;  // e.g. the first frame's display time
  FoveationGaze g = make(pursuit(100, 0), false, 0);
  EXPECT_FALSE(g.live());
  g.set_epoch(epoch);
  const FoveaGaze a = g.at(epoch + 255'000'000);
  ASSERT_TRUE(a.has_sample);
  EXPECT_EQ(a.query_ns, epoch + 255'000'000);
  EXPECT_EQ(a.sample_ns, epoch + 250'000'000);  // sample 25, on the caller's clock
  EXPECT_EQ(a.device_ns, 250'000'000 + 123'456'789);
  EXPECT_EQ(a.receive_ns, a.sample_ns);  // a recording carries no receive delay
  EXPECT_NEAR(az_deg(a.combined.dir), -2.5, 1e-9);
  EXPECT_GT(a.read_ns, 0);
  // Without an explicit epoch the first use is the start.
  FoveationGaze h = make(pursuit(100, 0), false, 0);
  EXPECT_EQ(h.at(5'000'000'000).sample_ns, 5'000'000'000);
  EXPECT_EQ(h.at(5'019'000'000).sample_ns, 5'010'000'000);
}

TEST(FoveationGaze, LiveSourcesRunOnTheHostClock) {
  const TimeNs t0 = 9'000'000'000'000;  // host monotonic stamps
  FoveationGaze g = make(pursuit(100, t0), true, 0);
  EXPECT_TRUE(g.live());
  g.set_epoch(123);  // no effect on a live source
  const FoveaGaze a = g.at(t0 + 255'000'000);
  ASSERT_TRUE(a.has_sample);
  EXPECT_EQ(a.sample_ns, t0 + 250'000'000);  // delivered later samples are not used
  EXPECT_EQ(a.receive_ns, t0 + 252'000'000);
  EXPECT_EQ(a.device_ns, 250'000'000 + t0 + 123'456'789);
  EXPECT_FALSE(g.at(t0 - 1).has_sample);  // nothing measured yet
}

TEST(FoveationGaze, SourceKindsSayWhetherTheyAreLive) {
  SourceOptions o;
  EXPECT_FALSE(FoveationGaze("synthetic:1", o).live());
  EXPECT_FALSE(FoveationGaze(fovea::devices::test::source_dir() + "/data/gaze/default.csv", o).live());
  EXPECT_FALSE(FoveationGaze("hid-capture:" + fovea::devices::test::source_dir() + "/data/gaze/hid-ms.hidcap", o).live());
  EXPECT_TRUE(FoveationGaze("hid-emulated:ms?seed=1&seconds=0.1", o).live());
  EXPECT_TRUE(FoveationGaze("hid-emulated:compact?seed=1&seconds=0.1&filters=ivt", o).live());
}

// Queries between samples at 60/120/250/1000 Hz, recorded and live, with and without
// prediction: the reported time is always the newest sample at or before the query.
TEST(FoveationGaze, TrueSampleTimesAtAnyRateWithAndWithoutPrediction) {
  std::mt19937_64 rng(13);
  for (double rate : {60.0, 120.0, 250.0, 1000.0})
    for (bool live : {false, true})
      for (TimeNs horizon : {TimeNs(0), TimeNs(20'000'000)}) {
        const TimeNs t0 = live ? 3'000'000'000'000 : 0;
        const std::vector<GazeSample> v = pursuit(rate, t0);
        FoveationGaze g = make(v, live, horizon);
        g.set_epoch(0);
        int predicted_better = 0, n = 0;
        for (TimeNs q = t0 + 100'000'000; q < v.back().t_ns; q += TimeNs(rng() % 7'000'000) + 1) {
          const FoveaGaze f = g.at(q);
          const auto newest = std::upper_bound(v.begin(), v.end(), q, [](TimeNs t, const GazeSample& s) { return t < s.t_ns; }) - 1;
          SCOPED_TRACE(testing::Message() << rate << " Hz, live " << live << ", horizon " << horizon << ", q " << q);
          ASSERT_TRUE(f.has_sample);
          ASSERT_EQ(f.sample_ns, newest->t_ns);
          ASSERT_EQ(f.device_ns, newest->device_time_ns);
          ASSERT_LE(f.sample_ns, f.query_ns);
          ASSERT_TRUE(f.combined.tracked());
          const glm::dvec3 truth = dir_deg(-5 + 10.0 * double(q - t0) * 1e-9);
          if (horizon == 0) {
            ASSERT_LT(angle_deg(f.combined.dir, newest->combined.dir), 1e-9);
          } else if (q - newest->t_ns > 200'000) {
            predicted_better += angle_deg(f.combined.dir, truth) < angle_deg(newest->combined.dir, truth);
            ++n;
          }
        }
        if (horizon > 0) {
          EXPECT_GT(n, 50);
          EXPECT_EQ(predicted_better, n) << rate << " Hz";  // pursuit: extrapolation always helps
        }
      }
}

// The loss policy with known answers (defaults: hold 400 ms, ease 300 ms, rest forward).
TEST(FoveationGaze, LossHoldsThenEasesToRestAndReturnsAtOnce) {
  std::vector<GazeSample> v;
  const TimeNs dt = 10'000'000;  // 100 Hz
  for (int i = 0; i <= 100; ++i) v.push_back(sample(i * dt, dir_deg(20)));                // tracked to 1.0 s
  for (int i = 101; i < 300; ++i) v.push_back(sample(i * dt, glm::dvec3(0), i < 140 ? kBlink : kLost));
  for (int i = 300; i < 320; ++i) v.push_back(sample(i * dt, dir_deg(-10)));             // back at 3.0 s
  FoveationGaze g = make(v, false, 0);
  g.set_epoch(0);
  const FoveaGaze tracked = g.at(1'000'000'000);
  EXPECT_EQ(tracked.combined.state, FoveaState::Tracking);
  const FoveaGaze blink = g.at(1'300'000'000);
  EXPECT_EQ(blink.combined.state, FoveaState::Holding);
  EXPECT_EQ(blink.combined.flags, kBlink);  // the tracker's flags stay visible
  EXPECT_LT(angle_deg(blink.combined.dir, dir_deg(20)), 1e-9);
  EXPECT_EQ(blink.sample_ns, 1'300'000'000);  // the newest sample, untracked
  EXPECT_EQ(g.at(1'400'000'000).combined.state, FoveaState::Holding);  // hold ends at 400 ms
  const FoveaGaze mid = g.at(1'550'000'000);  // halfway through the ease: smoothstep 0.5
  EXPECT_EQ(mid.combined.state, FoveaState::Easing);
  EXPECT_NEAR(angle_deg(mid.combined.dir, dir_deg(0)), 10.0, 1e-9);
  const FoveaGaze rest = g.at(1'700'000'000);
  EXPECT_EQ(rest.combined.state, FoveaState::Resting);
  EXPECT_LT(angle_deg(rest.combined.dir, dir_deg(0)), 1e-9);
  const FoveaGaze back = g.at(3'000'000'000);
  EXPECT_EQ(back.combined.state, FoveaState::Tracking);
  EXPECT_LT(angle_deg(back.combined.dir, dir_deg(-10)), 1e-9);
  // The ease has no jump: at most 1.5° per 10 ms step over the whole loss.
  FoveationGaze h = make(v, false, 0);
  h.set_epoch(0);
  glm::dvec3 prev = h.at(1'000'000'000).combined.dir;
  for (TimeNs t = 1'010'000'000; t < 3'000'000'000; t += dt) {
    const glm::dvec3 d = h.at(t).combined.dir;
    ASSERT_NEAR(glm::length(d), 1.0, 1e-12);
    ASSERT_LT(angle_deg(prev, d), 1.5) << t;
    prev = d;
  }
}

TEST(FoveationGaze, AStaleLiveDeviceHoldsFromItsLastSample) {
  const TimeNs t0 = 1'000'000'000'000;
  std::vector<GazeSample> v = pursuit(120, t0);  // one second, then nothing arrives
  FoveationGaze g = make(v, true, 20'000'000);
  const TimeNs last = v.back().t_ns;
  const FoveaGaze before = g.at(last + 5'000'000);  // the frames before: tracked, predicted
  EXPECT_TRUE(before.combined.tracked());
  const FoveaGaze f = g.at(last + 200'000'000);  // stale after 100 ms (max_gap_ns)
  EXPECT_EQ(f.sample_ns, last);
  EXPECT_EQ(f.combined.state, FoveaState::Holding);  // the fovea stays where it was
  EXPECT_LT(angle_deg(f.combined.dir, before.combined.dir), 1e-9);
  EXPECT_EQ(g.at(last + 1'000'000'000).combined.state, FoveaState::Resting);  // 400 + 300 ms after it
}

TEST(FoveationGaze, EachEyeFollowsItsOwnMeasurementOrTheCombinedGaze) {
  GazeSample s = sample(0, dir_deg(5));
  s.left.dir = dir_deg(7);
  s.right.flags = kLost;
  s.right.dir = glm::dvec3(0);
  FoveationGaze g = make({s}, false, 0);
  const FoveaGaze f = g.at(0);
  EXPECT_LT(angle_deg(f.left.dir, dir_deg(7)), 1e-9);
  EXPECT_LT(angle_deg(f.right.dir, dir_deg(5)), 1e-9);
  EXPECT_TRUE(f.right.tracked());
  // A measurement made elsewhere (the OpenXR eye-gaze action) goes through the same policy.
  const FoveaGaze u = g.use(600'000'000, sample(100'000'000, dir_deg(0), kLost));
  EXPECT_EQ(u.sample_ns, 100'000'000);
  EXPECT_EQ(u.left.state, FoveaState::Easing);  // 600 ms after the last tracked one at 0
  EXPECT_THROW(FoveationGaze(std::make_unique<TimelineSource>(std::make_unique<VectorStream>(std::vector<GazeSample>{}),
                                                              SourceOptions{}),
                             LossPolicy{-1, 0, {0, 0, -1}}),
               fovea::core::InputError);
}

// A raw HID capture is a recording: played from the epoch on the caller's clock, it follows
// the capture sample by sample instead of freezing on its last sample.
TEST(FoveationGaze, HidCaptureReplayFollowsTheRecording) {
  const std::string file = fovea::devices::test::source_dir() + "/data/gaze/hid-ms.hidcap";
  SourceOptions o;
  o.horizon_ns = 0;
  std::vector<GazeSample> rec;
  {
    hid::HidCaptureStream cap(file, o);
    GazeSample s;
    while (cap.next(s)) rec.push_back(s);
  }
  ASSERT_EQ(rec.size(), 240u);  // 2 s at 120 Hz
  FoveationGaze g("hid-capture:" + file, o);
  ASSERT_FALSE(g.live());
  const TimeNs epoch = fovea::core::now_ns() + 5'000'000'000;  // a display clock far from the capture's
  g.set_epoch(epoch);
  std::set<std::pair<double, double>> seen;
  int tracked = 0;
  for (TimeNs q = 0; q < 2'000'000'000; q += 11'111'111) {
    const FoveaGaze f = g.at(epoch + q);
    const auto newest = std::upper_bound(rec.begin(), rec.end(), q, [](TimeNs t, const GazeSample& s) { return t < s.t_ns; }) - 1;
    ASSERT_EQ(f.sample_ns, epoch + newest->t_ns) << q;
    ASSERT_EQ(f.device_ns, newest->device_time_ns) << q;
    if (newest->tracked()) {
      ++tracked;
      ASSERT_LT(angle_deg(f.combined.dir, newest->combined.dir), 1e-9) << q;
      seen.insert({f.combined.dir.x, f.combined.dir.y});
    }
  }
  EXPECT_GT(tracked, 150);
  EXPECT_GT(seen.size(), 100u);  // the fovea moves with the recording
}
