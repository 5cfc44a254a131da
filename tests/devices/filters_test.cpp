#include <cmath>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/devices/filters.hpp"
#include "fovea/devices/synthetic.hpp"
#include "fovea/devices/timeline.hpp"
#include "scripted.hpp"

using namespace fovea::devices;
using namespace fovea::devices::test;
using fovea::core::angle_deg;
using fovea::core::TimeNs;

namespace {
std::vector<GazeSample> run(std::unique_ptr<SampleStream> s) {
  std::vector<GazeSample> v;
  GazeSample g;
  while (s->next(g)) v.push_back(g);
  return v;
}
}  // namespace

TEST(OneEuro, SmoothsAtRestFollowsAtSpeedResetsAfterDropout) {
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0, 0.2);
  std::vector<GazeSample> in;
  const TimeNs dt = 8'333'333;
  for (int i = 0; i < 240; ++i) {  // 2 s fixation at 0°, a 10° saccade, 1 s fixation at 10°
    const double t = i * dt * 1e-9;
    const double x = t < 2.0 ? 0 : t < 2.043 ? 10 * (t - 2.0) / 0.043 : 10;
    in.push_back(sample(i * dt, dir_deg(x + noise(rng), noise(rng))));
  }
  for (int i = 240; i < 360; ++i) in.push_back(sample(i * dt, dir_deg(10 + noise(rng), noise(rng))));
  for (int i = 360; i < 400; ++i) in.push_back(sample(i * dt, dir_deg(0, 0), kLost));  // 330 ms dropout
  in.push_back(sample(400 * dt, dir_deg(-5, 3)));
  auto filtered = [&](double beta) {
    FilterParams p;
    p.one_euro.beta = beta;
    return run(apply_filters(std::make_unique<VectorStream>(in), "oneeuro", p));
  };
  const auto out = filtered(0.05), slow = filtered(0.0);
  ASSERT_EQ(out.size(), in.size());
  double raw2 = 0, filt2 = 0;
  for (int i = 60; i < 230; ++i) {
    raw2 += std::pow(angle_deg(in[i].combined.dir, dir_deg(0, 0)), 2);
    filt2 += std::pow(angle_deg(out[i].combined.dir, dir_deg(0, 0)), 2);
  }
  EXPECT_LT(std::sqrt(filt2 / raw2), 0.35);  // jitter at rest strongly reduced
  const int after = 247;                      // ~15 ms after landing
  EXPECT_LT(angle_deg(out[after].combined.dir, dir_deg(10, 0)), 1.5);
  EXPECT_GT(angle_deg(slow[after].combined.dir, dir_deg(10, 0)), 4.0);  // beta = 0 lags far behind
  EXPECT_EQ(out[370].combined.flags, kLost);
  EXPECT_EQ(out[400].combined.dir, in[400].combined.dir);  // reset: no smoothing across the dropout
}

TEST(IvtStage, GapFillBelow75msAndSaccadeClasses) {
  std::vector<GazeSample> in;
  const TimeNs dt = 4'000'000;  // 250 Hz
  int i = 0;
  for (; i < 50; ++i) in.push_back(sample(i * dt, dir_deg(0, 0)));
  for (; i < 62; ++i) in.push_back(sample(i * dt, dir_deg(0, 0), kLost));  // 48 ms: filled
  for (; i < 70; ++i) in.push_back(sample(i * dt, dir_deg(1, 0)));
  for (; i < 95; ++i) in.push_back(sample(i * dt, dir_deg(0, 0), kLost));  // 100 ms: kept lost
  for (; i < 100; ++i) in.push_back(sample(i * dt, dir_deg(1, 0)));
  for (; i < 110; ++i) in.push_back(sample(i * dt, dir_deg(1 + (i - 99) * 2.0, 0)));  // 500 °/s
  for (; i < 130; ++i) in.push_back(sample(i * dt, dir_deg(21, 0)));
  in[75] = sample(75 * dt, dir_deg(0, 0), kBlink);  // blinks are never filled
  const auto out = run(apply_filters(std::make_unique<VectorStream>(in), "ivt", FilterParams{}));
  ASSERT_EQ(out.size(), in.size());
  for (int k = 50; k < 62; ++k) {
    EXPECT_TRUE(out[k].tracked()) << k;
    EXPECT_LT(out[k].combined.confidence, 1.0);
    EXPECT_EQ(out[k].t_ns, in[k].t_ns);
  }
  EXPECT_NEAR(std::atan2(out[56].combined.dir.x, -out[56].combined.dir.z) * 180 / M_PI, 28.0 / 52.0, 0.01);  // interpolated between samples 49 and 62
  for (int k = 70; k < 95; ++k) EXPECT_FALSE(out[k].tracked()) << k;
  EXPECT_EQ(out[75].combined.flags, kBlink);
  EXPECT_EQ(out[40].motion, Motion::Fixation);
  int saccade = 0;
  for (int k = 100; k < 112; ++k) saccade += out[k].motion == Motion::Saccade;
  EXPECT_GE(saccade, 8);
  EXPECT_EQ(out[128].motion, Motion::Fixation);
  EXPECT_THROW(apply_filters(std::make_unique<VectorStream>(in), "ivt,kalman", FilterParams{}), fovea::core::InputError);
}

TEST(Prediction, NoExtrapolationAcrossSaccadeOnsetLandingAfterPeak) {
  SynthParams sp;
  sp.seed = 9;
  sp.seconds = 60;
  sp.rate_hz = 1000;
  sp.noise_deg = 0;
  sp.dropout_per_s = 0;
  SyntheticStream syn(sp);
  std::vector<SynthEvent> sacc;
  syn.on_event([&](const SynthEvent& e) {
    if (e.kind == SynthEvent::Saccade && e.amplitude_deg > 8) sacc.push_back(e);
  });
  std::vector<GazeSample> all;
  GazeSample g;
  while (syn.next(g)) all.push_back(g);
  GazePredictor pred;
  int checked = 0, landing_better = 0;
  for (const SynthEvent& e : sacc) {
    const std::size_t on = static_cast<std::size_t>(e.start_ns / 1'000'000), end = static_cast<std::size_t>(e.end_ns / 1'000'000);
    if (on < 100 || end + 30 >= all.size() || all[on].combined.flags != kTracked) continue;
    bool clean = true;
    for (std::size_t k = on - 60; k <= end + 20; ++k) clean = clean && all[k].tracked();
    if (!clean) continue;
    // Early in the saccade (accelerating): hold, never extrapolate.
    std::deque<GazeSample> h(all.begin() + static_cast<long>(on) - 60, all.begin() + static_cast<long>(on) + 6);
    const GazeSample p = pred.predict(h, h.back().t_ns + 20'000'000, 20'000'000);
    EXPECT_LT(angle_deg(p.combined.dir, h.back().combined.dir), 1e-9);
    // After the peak: the main-sequence landing estimate beats holding.
    const std::size_t late = on + static_cast<std::size_t>((end - on) * 0.7);
    std::deque<GazeSample> h2(all.begin() + static_cast<long>(on) - 60, all.begin() + static_cast<long>(late) + 1);
    const GazeSample p2 = pred.predict(h2, h2.back().t_ns + 20'000'000, 20'000'000);
    const glm::dvec3 truth = all[std::min(late + 20, all.size() - 1)].combined.dir;
    landing_better += angle_deg(p2.combined.dir, truth) < angle_deg(h2.back().combined.dir, truth);
    ++checked;
  }
  ASSERT_GT(checked, 20);
  EXPECT_GT(landing_better, 0.8 * checked);
}

TEST(Prediction, ConstantVelocityInPursuitAndHorizonThroughTheTimeline) {
  std::vector<GazeSample> in;
  const TimeNs dt = 8'333'333;
  for (int i = 0; i < 60; ++i) in.push_back(sample(i * dt, dir_deg(20.0 * i * dt * 1e-9, 0)));  // 20 °/s pursuit
  GazePredictor pred;
  std::deque<GazeSample> h(in.begin(), in.begin() + 40);
  const GazeSample p = pred.predict(h, h.back().t_ns + 20'000'000, 20'000'000);
  const double expect = 20.0 * (h.back().t_ns + 20'000'000) * 1e-9;
  EXPECT_NEAR(std::atan2(p.combined.dir.x, -p.combined.dir.z) * 180 / M_PI, expect, 0.02);

  auto live = std::make_unique<VectorStream>(in, true);
  live->limit_ = 40;
  SourceOptions o;
  o.horizon_ns = 20'000'000;
  TimelineSource src(std::move(live), o);
  const TimeNs newest = in[39].t_ns;
  const GazeSample a = src.sample_at(newest + 20'000'000), b = src.sample_at(newest + 90'000'000);
  EXPECT_EQ(a.combined.dir, b.combined.dir);  // never further than the horizon
  EXPECT_EQ(a.t_ns, newest);  // predicted, but measured at the newest sample
  EXPECT_EQ(b.t_ns, newest);
  EXPECT_GT(angle_deg(a.combined.dir, in[39].combined.dir), 0.3);
  // Lost newest sample: hold, no prediction from stale velocity.
  std::deque<GazeSample> lost = h;
  lost.push_back(sample(h.back().t_ns + dt, dir_deg(0, 0), kLost));
  EXPECT_EQ(pred.predict(lost, lost.back().t_ns + 10'000'000, 20'000'000).combined.flags, kLost);
}

// A gaze step (the eye landed between two samples, as at low rates or in a recording that
// jumps): once the newest interval is still, the prediction stays within 1° of the landing
// point, whatever the step and the rate (before: the pursuit window spanned the jump and
// extrapolated it, 6° past a 32° step).
TEST(Prediction, AStepIsNotExtrapolatedPastItsLanding) {
  GazePredictor pred;
  for (const double step : {5.0, 32.0})
    for (const TimeNs dt : {TimeNs(4'000'000), TimeNs(8'333'333), TimeNs(16'666'667)}) {
      std::deque<GazeSample> h;
      for (int i = 0; i < 20; ++i) h.push_back(sample(i * dt, dir_deg(i < 15 ? -step / 2 : step / 2, 0)));
      for (const TimeNs ahead : {TimeNs(0), TimeNs(10'000'000), TimeNs(20'000'000)}) {
        const GazeSample p = pred.predict(h, h.back().t_ns + ahead, 20'000'000);
        EXPECT_LE(angle_deg(p.combined.dir, dir_deg(step / 2, 0)), 1.0) << step << " deg, dt " << dt << ", ahead " << ahead;
      }
    }
}

TEST(Filters, ComposeOnAnySourceByUri) {
  SourceOptions o;
  auto src = open_gaze_source("synthetic:3?rate=250&filters=ivt,oneeuro", o);
  for (TimeNs t = 0; t < 5'000'000'000; t += 11'111'111) {
    const GazeSample s = src->sample_at(t);
    ASSERT_NEAR(glm::length(s.combined.dir), 1.0, 1e-9);
    ASSERT_LT(s.combined.dir.z, 0);
  }
  EXPECT_THROW(open_gaze_source("synthetic:3?filters=median", o), fovea::core::InputError);
  EXPECT_THROW(open_gaze_source("synthetic:3?filters=hold", o), fovea::core::InputError);  // the foveation gaze's policy
}
