// The tracker model: known delays at 60–1000 Hz, bounded in-order jitter, dropout fraction
// and burst length, noise RMS, blinks and saccade loss, determinism, the host-clock mode
// (ordering and invariants only) and the URI keys with their duration syntax.
#include <chrono>
#include <cmath>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "fovea/core/duration.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/view.hpp"
#include "fovea/devices/foveation_gaze.hpp"
#include "fovea/devices/synthetic.hpp"
#include "fovea/devices/timeline.hpp"
#include "fovea/devices/tracker_model.hpp"
#include "scripted.hpp"

using namespace fovea::devices;
using namespace fovea::devices::test;
using fovea::core::angle_deg;
using fovea::core::InputError;
using fovea::core::TimeNs;

namespace {
constexpr TimeNs kMs = 1'000'000;

// Clean synthetic gaze at 1 kHz: the true eye.
std::unique_ptr<SampleStream> true_eye(std::uint64_t seed, SynthTask task = SynthTask::Search) {
  SynthParams p;
  p.seed = seed;
  p.task = task;
  p.rate_hz = 1000;
  p.noise_deg = 0;
  p.dropout_per_s = 0;
  return std::make_unique<SyntheticStream>(p);
}

// A true eye that never moves (a one-sample recording holds its sample for ever).
std::unique_ptr<SampleStream> still_eye() {
  return std::make_unique<VectorStream>(std::vector<GazeSample>{sample(0, dir_deg(5, -3))});
}

TrackerParams clean(double rate_hz, TimeNs delay_ns) {
  TrackerParams p = tracker_preset("ideal");
  p.rate_hz = rate_hz;
  p.delay_ns = delay_ns;
  return p;
}

std::unique_ptr<TrackerModel> model(std::unique_ptr<SampleStream> truth, const TrackerParams& p, TimeNs horizon_ns = 0) {
  SourceOptions o;
  o.horizon_ns = 0;
  SourceOptions mo;
  mo.horizon_ns = horizon_ns;
  return std::make_unique<TrackerModel>(std::make_unique<TimelineSource>(std::move(truth), o), p, mo);
}

TimeNs instant(std::int64_t k, double rate_hz) { return std::llround(static_cast<double>(k) * 1e9 / rate_hz); }

// Every sample of a model without jitter, in order (sample k is delivered exactly at t_k + delay).
std::vector<GazeSample> walk(TrackerModel& m, std::int64_t n) {
  std::vector<GazeSample> v;
  for (std::int64_t k = 0; k < n; ++k) v.push_back(m.sample_at(instant(k, m.params().rate_hz) + m.params().delay_ns));
  return v;
}
}  // namespace

TEST(TrackerModel, DelayIsExactAtEveryRate) {
  for (const double rate : {60.0, 120.0, 250.0, 1000.0}) {
    SCOPED_TRACE(rate);
    const TimeNs delay = 20 * kMs;
    auto m = model(true_eye(7), clean(rate, delay));
    std::mt19937_64 rng(11);
    std::uniform_int_distribution<TimeNs> pick(0, 5'000 * kMs);  // random order: seeks back past the 2 s window
    int checked = 0;
    for (int i = 0; i < 400; ++i) {
      const TimeNs t = pick(rng);
      const GazeSample s = m->sample_at(t);
      if (t < delay) {
        EXPECT_EQ(s.t_ns, kNoSample);
        continue;
      }
      // The newest sample instant at or before t − D.
      auto k = static_cast<std::int64_t>(std::floor(static_cast<double>(t - delay) * rate * 1e-9));
      while (instant(k + 1, rate) <= t - delay) ++k;
      while (instant(k, rate) > t - delay) --k;
      ASSERT_EQ(s.t_ns, instant(k, rate)) << "query " << t;
      EXPECT_EQ(s.device_time_ns, s.t_ns);
      EXPECT_EQ(s.host_time_ns - s.t_ns, delay);  // the measured tracker delay is D exactly
      const GazeSample truth = m->truth_at(s.t_ns);
      EXPECT_EQ(s.combined.flags, truth.combined.flags);
      EXPECT_EQ(s.combined.dir, truth.combined.dir);
      EXPECT_EQ(s.left.dir, truth.left.dir);
      EXPECT_EQ(s.right.dir, truth.right.dir);
      ++checked;
    }
    EXPECT_GT(checked, 380);
  }
}

TEST(TrackerModel, JitterStaysWithinItsBoundAndKeepsOrder) {
  TrackerParams p = clean(250, 10 * kMs);
  p.jitter_ns = 4 * kMs;
  auto m = model(true_eye(3), p);
  TimeNs last_t = -1, last_host = -1, lo = INT64_MAX, hi = INT64_MIN;
  int distinct = 0;
  for (TimeNs t = 0; t < 2'000 * kMs; t += kMs / 10) {
    const GazeSample s = m->sample_at(t);
    if (s.t_ns == kNoSample) continue;
    ASSERT_LE(s.host_time_ns, t);  // never a sample delivered after the query
    if (s.t_ns == last_t) continue;
    ASSERT_GT(s.t_ns, last_t);
    ASSERT_GE(s.host_time_ns, last_host);
    const TimeNs extra = s.host_time_ns - s.t_ns - p.delay_ns;
    ASSERT_GE(extra, 0);
    ASSERT_LE(extra, p.jitter_ns);
    lo = std::min(lo, extra);
    hi = std::max(hi, extra);
    last_t = s.t_ns;
    last_host = s.host_time_ns;
    ++distinct;
  }
  EXPECT_GT(distinct, 400);               // most of the 500 samples are seen at 0.1 ms steps
  EXPECT_GT(hi - lo, 3 * p.jitter_ns / 4);  // the jitter is there, spread over its range
}

TEST(TrackerModel, DropoutFractionAndBurstLength) {
  TrackerParams p = clean(120, 0);
  p.dropout = 0.05;
  p.burst_ns = 40 * kMs;  // 4.8 samples at 120 Hz
  auto m = model(still_eye(), p);
  const auto v = walk(*m, 120 * 600);  // ten minutes
  int lost = 0, bursts = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (v[i].tracked()) continue;
    EXPECT_EQ(v[i].combined.flags, kLost);
    ++lost;
    if (i == 0 || v[i - 1].tracked()) ++bursts;
  }
  const double fraction = double(lost) / double(v.size());
  EXPECT_NEAR(fraction, 0.05, 0.006);
  EXPECT_NEAR(double(lost) / bursts, 4.8, 0.5);
}

TEST(TrackerModel, NoiseHasItsRms) {
  TrackerParams p = clean(500, 0);
  p.noise_deg = 0.5;
  auto m = model(still_eye(), p);
  const glm::dvec3 truth = dir_deg(5, -3);
  double eye2 = 0, comb2 = 0;
  const auto v = walk(*m, 20'000);
  for (const GazeSample& s : v) {
    ASSERT_TRUE(s.tracked());
    eye2 += std::pow(angle_deg(s.left.dir, truth), 2);
    comb2 += std::pow(angle_deg(s.combined.dir, truth), 2);
  }
  EXPECT_NEAR(std::sqrt(eye2 / double(v.size())), 0.5, 0.015);
  // Independent eyes: their mean has 1/√2 of the noise.
  EXPECT_NEAR(std::sqrt(comb2 / double(v.size())), 0.5 / std::sqrt(2.0), 0.015);
  // No noise: the truth itself.
  auto exact = model(still_eye(), clean(500, 0));
  for (const GazeSample& s : walk(*exact, 100)) EXPECT_EQ(s.left.dir, truth);
}

TEST(TrackerModel, BlinksAreInvalidAndSaccadesCanBeLost) {
  // 1 s at 1 kHz: a blink at 300–500 ms, a 20° saccade at 600–640 ms (500 °/s).
  std::vector<GazeSample> eye;
  for (TimeNs t = 0; t < 1'000 * kMs; t += kMs) {
    const double az = t < 600 * kMs ? 0 : t >= 640 * kMs ? 20 : 20.0 * double(t - 600 * kMs) / double(40 * kMs);
    eye.push_back(sample(t, dir_deg(az), t >= 300 * kMs && t < 500 * kMs ? kBlink : kTracked));
  }
  for (const double loss : {0.0, 100.0}) {
    TrackerParams p = clean(250, 8 * kMs);
    p.saccade_loss_deg_s = loss;
    auto m = model(std::make_unique<VectorStream>(eye), p);
    for (const GazeSample& s : walk(*m, 249)) {
      const TimeNs t = s.t_ns;
      if (t >= 300 * kMs && t < 500 * kMs) {
        EXPECT_EQ(s.combined.flags, kBlink) << t;
      } else if (loss > 0 && t > 600 * kMs && t <= 640 * kMs) {
        EXPECT_EQ(s.combined.flags, kLost) << t;  // moved faster than 100 °/s since the last sample
      } else {
        EXPECT_TRUE(s.tracked()) << t;
      }
    }
  }
}

TEST(TrackerModel, SeededAndRepeatable) {
  TrackerParams p = tracker_preset("fove0");
  auto a = model(true_eye(5), p), b = model(true_eye(5), p);
  p.seed = 2;
  auto c = model(true_eye(5), p);
  int differ = 0;
  for (TimeNs t = 0; t < 1'000 * kMs; t += 7 * kMs) {
    const GazeSample x = a->sample_at(t), y = b->sample_at(t), z = c->sample_at(t);
    ASSERT_EQ(x.t_ns, y.t_ns);
    ASSERT_EQ(x.host_time_ns, y.host_time_ns);
    ASSERT_EQ(x.combined.dir, y.combined.dir);
    differ += x.t_ns != kNoSample && x.combined.dir != z.combined.dir;
  }
  EXPECT_GT(differ, 100);
}

TEST(TrackerModel, SlowIsNotStale) {
  // A delay beyond max_gap (100 ms) still delivers tracked samples; a tracker that stops
  // delivering goes stale. (A constant delay is the tracker's, not a loss.)
  auto m = model(still_eye(), clean(120, 150 * kMs));
  EXPECT_EQ(m->sample_at(149 * kMs).t_ns, kNoSample);
  const GazeSample s = m->sample_at(1'000 * kMs);
  EXPECT_TRUE(s.tracked());
  EXPECT_EQ(s.host_time_ns - s.t_ns, 150 * kMs);
}

TEST(TrackerModel, FoveationGazeReportsMeasurementAndDelivery) {
  const TimeNs epoch = 5'000'000'000'000, delay = 12 * kMs;
  FoveationGaze g(model(true_eye(4), clean(250, delay)));
  EXPECT_FALSE(g.live());
  g.set_epoch(epoch);
  for (const TimeNs q : {TimeNs(100 * kMs), TimeNs(1'234'567'891)}) {
    const FoveaGaze f = g.at(epoch + q);
    ASSERT_TRUE(f.has_sample);
    EXPECT_EQ(f.sample_ns, epoch + (q - delay) / (4 * kMs) * (4 * kMs));  // the newest 250 Hz instant ≤ q − D
    EXPECT_EQ(f.device_ns, f.sample_ns - epoch);
    EXPECT_EQ(f.receive_ns - f.sample_ns, delay);
  }
}

TEST(TrackerModel, GroundTruthMustNotBeLive) {
  SourceOptions o;
  auto live = std::make_unique<TimelineSource>(std::make_unique<VectorStream>(std::vector<GazeSample>{}, true), o);
  EXPECT_THROW(TrackerModel(std::move(live), tracker_preset("fove0"), o), InputError);
  TrackerParams p = tracker_preset("fove0");
  p.rate_hz = 5;
  EXPECT_THROW(model(still_eye(), p), InputError);
  EXPECT_THROW(tracker_preset("eyelink"), InputError);
}

TEST(TrackerModel, HostClockDeliversSamplesInOrder) {
  TrackerParams p = clean(1000, 5 * kMs);
  p.host_clock = true;
  p.noise_deg = 0.1;
  auto owned = model(true_eye(9), p);
  TrackerModel& m = *owned;
  EXPECT_TRUE(m.is_live());
  const TimeNs epoch = m.epoch_ns();
  EXPECT_EQ(m.sample_at(epoch + p.delay_ns - 1).t_ns, kNoSample);  // measured at 0, not delivered yet
  TimeNs last_t = kNoSample;
  int distinct = 0;
  // Poll until 20 distinct samples came (a generous bound, not a timing assertion).
  for (int i = 0; i < 20'000 && distinct < 20; ++i) {
    const TimeNs before = fovea::core::now_ns();
    const GazeSample s = m.latest();
    if (s.t_ns != kNoSample && s.t_ns != last_t) {
      ASSERT_GT(s.t_ns, last_t);
      EXPECT_EQ(s.device_time_ns, s.t_ns - epoch);  // the tracker's clock counts from its start
      EXPECT_EQ((s.t_ns - epoch) % kMs, 0);          // measured at a 1 kHz instant
      EXPECT_GE(s.host_time_ns, s.t_ns + p.delay_ns);  // received no earlier than the model says
      EXPECT_LE(s.host_time_ns, fovea::core::now_ns());
      EXPECT_GE(fovea::core::now_ns(), before);
      last_t = s.t_ns;
      ++distinct;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  EXPECT_EQ(distinct, 20);
  // The foveation gaze takes it as a live source on the host clock.
  FoveationGaze g(std::move(owned));
  EXPECT_TRUE(g.live());
  const TimeNs now = fovea::core::now_ns();
  const FoveaGaze f = g.at(now);
  ASSERT_TRUE(f.has_sample);
  EXPECT_LE(f.sample_ns, now - p.delay_ns);
  EXPECT_GE(f.receive_ns, f.sample_ns + p.delay_ns);
}

TEST(TrackerModel, OpenedFromUriKeys) {
  SourceOptions o;
  auto src = open_gaze_source(
      "synthetic:3?rate=1000&noise=0&dropouts=0&tracker=fove0&tracker_jitter=0&tracker_noise=0&tracker_dropout=0&horizon_ms=0", o);
  auto* m = dynamic_cast<TrackerModel*>(src.get());
  ASSERT_NE(m, nullptr);
  EXPECT_FALSE(src->is_live());
  EXPECT_EQ(m->params().rate_hz, 120);
  EXPECT_EQ(m->params().delay_ns, 15 * kMs);
  const GazeSample s = src->sample_at(1'000 * kMs);
  EXPECT_EQ(s.host_time_ns - s.t_ns, 15 * kMs);
  EXPECT_EQ(s.t_ns, instant(118, 120));  // the newest 120 Hz instant ≤ 985 ms
  EXPECT_EQ(s.combined.dir, m->truth_at(s.t_ns).combined.dir);

  // Overrides without a preset start from fove0; times take a unit, bare numbers are ms.
  auto k = open_gaze_source("synthetic:1?tracker_delay=500us&tracker_jitter=3&tracker_rate=250", o);
  const auto& q = dynamic_cast<TrackerModel&>(*k).params();
  EXPECT_EQ(q.delay_ns, 500'000);
  EXPECT_EQ(q.jitter_ns, 3 * kMs);
  EXPECT_EQ(q.rate_hz, 250);
  EXPECT_EQ(q.name, "fove0");
  // Without tracker keys: the source as it was.
  EXPECT_EQ(dynamic_cast<TrackerModel*>(open_gaze_source("synthetic:1", o).get()), nullptr);

  for (const char* bad : {"synthetic:1?tracker=eyelink", "synthetic:1?tracker_delay=20xs", "synthetic:1?tracker_delay=-1ms",
                          "synthetic:1?tracker_rate=5", "synthetic:1?tracker_clock=wall", "synthetic:1?tracker_dropout=1",
                          "synthetic:1?tracker=fove0&filters=ivt"})
    EXPECT_THROW(open_gaze_source(bad, o), InputError) << bad;
  EXPECT_THROW(open_sample_stream("synthetic:1?tracker=fove0", o), InputError);
}

TEST(Duration, UnitsAndBareMilliseconds) {
  using fovea::core::parse_duration_ns;
  EXPECT_EQ(parse_duration_ns("20ms", "x"), 20'000'000);
  EXPECT_EQ(parse_duration_ns("20", "x"), 20'000'000);
  EXPECT_EQ(parse_duration_ns("1.5ms", "x"), 1'500'000);
  EXPECT_EQ(parse_duration_ns("250us", "x"), 250'000);
  EXPECT_EQ(parse_duration_ns("7ns", "x"), 7);
  EXPECT_EQ(parse_duration_ns("0.25s", "x"), 250'000'000);
  EXPECT_EQ(parse_duration_ns("0", "x"), 0);
  for (const char* bad : {"", "ms", "-2ms", "2 ms", "2msec", "nan", "inf", "1e300s"}) EXPECT_THROW(parse_duration_ns(bad, "x"), InputError) << bad;
  try {
    parse_duration_ns("3h", "--tracker-delay");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--tracker-delay"), std::string::npos);
  }
}

TEST(Duration, PrintedToThreeSignificantDigits) {
  using fovea::core::significant_decimals;
  // A CPU device's frame, a GPU's, a GPU's kernel, a cost per 1000 samples.
  EXPECT_EQ(significant_decimals(1997.4), 0);
  EXPECT_EQ(significant_decimals(452.0), 0);
  EXPECT_EQ(significant_decimals(99.96), 1);  // prints 100.0: one digit more, never less
  EXPECT_EQ(significant_decimals(45.3), 1);
  EXPECT_EQ(significant_decimals(4.47), 2);
  EXPECT_EQ(significant_decimals(-4.47), 2);
  EXPECT_EQ(significant_decimals(0.0123), 4);
  EXPECT_EQ(significant_decimals(0.4, 2), 2);
  EXPECT_EQ(significant_decimals(5.2, 2), 1);
  for (double v : {0.0, std::nan(""), HUGE_VAL, -HUGE_VAL}) EXPECT_EQ(significant_decimals(v), 0) << v;
  EXPECT_EQ(significant_decimals(1e-300), 12);  // capped: a denormal-sized time prints as 0.000000000000
  EXPECT_EQ(fovea::core::fixed_significant(4.4712), "4.47");
  EXPECT_EQ(fovea::core::fixed_significant(1997.4), "1997");
  EXPECT_EQ(fovea::core::fixed_significant(0.4, 2), "0.40");
}
