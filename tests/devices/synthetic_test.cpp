#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/devices/analysis.hpp"
#include "fovea/devices/synthetic.hpp"

using namespace fovea::devices;
using fovea::core::TimeNs;

namespace {
struct SynthRun {
  std::vector<SynthEvent> events;
  std::vector<GazeSample> samples;
};
SynthRun generate(SynthParams p, bool keep_samples) {
  SyntheticStream s(p);
  SynthRun r;
  s.on_event([&](const SynthEvent& e) { r.events.push_back(e); });
  GazeSample g;
  while (s.next(g))
    if (keep_samples) r.samples.push_back(g);
  return r;
}
double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}
}  // namespace

TEST(Synthetic, ReproducibleFromTheSeed) {
  SynthParams p;
  p.seed = 11;
  p.seconds = 3;
  const SynthRun a = generate(p, true), b = generate(p, true);
  ASSERT_EQ(a.samples.size(), 360u);
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    ASSERT_EQ(a.samples[i].combined.dir, b.samples[i].combined.dir);
    ASSERT_EQ(a.samples[i].combined.flags, b.samples[i].combined.flags);
  }
  p.seed = 12;
  const SynthRun c = generate(p, true);
  EXPECT_NE(a.samples[200].combined.dir, c.samples[200].combined.dir);
  for (const GazeSample& g : a.samples) {
    EXPECT_NEAR(glm::length(g.combined.dir), 1.0, 1e-9);
    EXPECT_TRUE(std::isfinite(g.left.dir.x + g.right.dir.y));
  }
}

TEST(Synthetic, FixationDurationMedianPerTask) {
  for (auto [task, med] : {std::pair{SynthTask::Reading, 230.0}, std::pair{SynthTask::Search, 275.0}}) {
    SynthParams p;
    p.task = task;
    p.seed = 21;
    p.seconds = 600;
    p.rate_hz = 250;
    std::vector<double> d;
    for (const SynthEvent& e : generate(p, false).events)
      if (e.kind == SynthEvent::Fixation) d.push_back(static_cast<double>(e.end_ns - e.start_ns) * 1e-6);
    ASSERT_GT(d.size(), 1000u);
    // The sampled median is quantised to the 4 ms sample period and ends at saccade onset.
    EXPECT_NEAR(median(d), med, 0.06 * med) << synth_task_name(task);
  }
}

TEST(Synthetic, SaccadesFollowTheMainSequence) {
  SynthParams p;
  p.task = SynthTask::Search;
  p.seed = 5;
  p.seconds = 300;
  p.rate_hz = 1000;
  p.noise_deg = 0;
  p.dropout_per_s = 0;
  const SynthRun r = generate(p, true);
  // Duration fit from the samples themselves: the time the eye moves faster than 5 °/s.
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0, peaks_ok = 0, peaks = 0;
  for (const SynthEvent& e : r.events) {
    if (e.kind != SynthEvent::Saccade || e.amplitude_deg < 2) continue;
    const std::size_t i0 = static_cast<std::size_t>(e.start_ns / 1'000'000), i1 = static_cast<std::size_t>(e.end_ns / 1'000'000);
    if (i1 + 2 >= r.samples.size() || i0 < 2) continue;
    double vmax = 0;
    int moving = 0;
    for (std::size_t i = i0 - 1; i <= i1 + 1; ++i) {
      const double v = fovea::core::angle_deg(r.samples[i - 1].combined.dir, r.samples[i].combined.dir) / 1e-3;
      vmax = std::max(vmax, v);
      moving += v > 5;
    }
    const double dur = moving;  // ms at 1 kHz
    sx += e.amplitude_deg;
    sy += dur;
    sxx += e.amplitude_deg * e.amplitude_deg;
    sxy += e.amplitude_deg * dur;
    ++n;
    ++peaks;
    peaks_ok += std::abs(vmax - main_sequence::peak_velocity_deg_s(e.amplitude_deg)) <
                0.1 * main_sequence::peak_velocity_deg_s(e.amplitude_deg);
  }
  ASSERT_GT(n, 300);
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx), icpt = (sy - slope * sx) / n;
  EXPECT_NEAR(slope, 2.2, 0.15);
  EXPECT_NEAR(icpt, 21, 3.0);
  EXPECT_GT(peaks_ok, 0.95 * peaks);  // measured peak velocity within 10% of Vmax(1 − e^(−A/C))
}

TEST(Synthetic, BlinkRatesAndInvalidSamples) {
  for (auto [task, rate] : {std::pair{SynthTask::Reading, 4.5}, std::pair{SynthTask::Search, 17.0}}) {
    SynthParams p;
    p.task = task;
    p.seed = 8;
    p.seconds = 3600;
    p.rate_hz = 60;
    SyntheticStream s(p);
    int blinks = 0;
    std::vector<double> dur;
    s.on_event([&](const SynthEvent& e) {
      if (e.kind == SynthEvent::Blink) {
        ++blinks;
        dur.push_back(static_cast<double>(e.end_ns - e.start_ns) * 1e-6);
      }
    });
    GazeSample g;
    std::uint64_t blink_samples = 0;
    while (s.next(g)) blink_samples += (g.combined.flags == kBlink);
    const double per_min = blinks / 60.0;
    EXPECT_NEAR(per_min, rate, 0.12 * rate) << synth_task_name(task);
    EXPECT_GE(*std::min_element(dur.begin(), dur.end()), 100.0);
    EXPECT_LE(*std::max_element(dur.begin(), dur.end()), 400.0);
    EXPECT_NEAR(static_cast<double>(blink_samples) / 60.0, median(dur) * 1e-3 * blinks, 0.25 * median(dur) * 1e-3 * blinks);
  }
}

TEST(Synthetic, MicrosaccadesAndPursuit) {
  SynthParams p;
  p.task = SynthTask::FixationGrid;
  p.seed = 2;
  p.seconds = 300;
  p.rate_hz = 500;
  int micro = 0;
  for (const SynthEvent& e : generate(p, false).events)
    if (e.kind == SynthEvent::Microsaccade) {
      ++micro;
      EXPECT_GE(e.amplitude_deg, 0.099);
      EXPECT_LE(e.amplitude_deg, 1.001);
    }
  EXPECT_GT(micro / 300.0, 1.0);  // 1–2 per second of fixation
  EXPECT_LT(micro / 300.0, 2.0);

  p.task = SynthTask::Pursuit;
  p.noise_deg = 0;
  p.dropout_per_s = 0;
  p.rate_hz = 1000;
  p.seconds = 60;
  const SynthRun r = generate(p, true);
  int catchups = 0;
  std::vector<char> in_sacc(r.samples.size(), 0);
  for (const SynthEvent& e : r.events)
    if (e.kind == SynthEvent::CatchUpSaccade) {
      ++catchups;
      for (TimeNs t = e.start_ns / 1'000'000; t <= e.end_ns / 1'000'000 + 1 && t < TimeNs(in_sacc.size()); ++t) in_sacc[t] = 1;
    }
  EXPECT_GT(catchups, 20);
  double vmax = 0;
  for (std::size_t i = 1; i + 100 < r.samples.size(); ++i)  // the last saccade may be unfinished
    if (!in_sacc[i]) vmax = std::max(vmax, fovea::core::angle_deg(r.samples[i - 1].combined.dir, r.samples[i].combined.dir) / 1e-3);
  EXPECT_LE(vmax, 30.5);  // pursuit never faster than 30 °/s (per-eye vergence aside)
  EXPECT_GT(vmax, 25.0);
}

TEST(Synthetic, NoiseRmsAndColour) {
  for (double colour : {0.0, 0.8}) {
    SynthParams p;
    p.seed = 4;
    p.seconds = 60;
    p.rate_hz = 250;
    p.noise_color = colour;
    p.noise_deg = 0;  // the generator draws the same random numbers whatever the noise level,
    const SynthRun clean = generate(p, true);
    p.noise_deg = 0.2;  // so the difference of two runs is exactly the noise
    const SynthRun noisy = generate(p, true);
    ASSERT_EQ(clean.samples.size(), noisy.samples.size());
    double s2 = 0, d2 = 0, prev = 0;
    const std::size_t n = clean.samples.size();
    for (std::size_t i = 0; i < n; ++i) {
      const auto& a = clean.samples[i].left.dir;
      const auto& b = noisy.samples[i].left.dir;
      const double x = (std::atan2(b.x, -b.z) - std::atan2(a.x, -a.z)) * 180 / M_PI;
      s2 += x * x;
      if (i) d2 += (x - prev) * (x - prev);
      prev = x;
    }
    const double sd = std::sqrt(s2 / n), s2s = std::sqrt(d2 / (n - 1));
    EXPECT_NEAR(sd, 0.2, colour > 0 ? 0.02 : 0.01) << colour;
    EXPECT_NEAR(s2s / sd, std::sqrt(2 * (1 - colour)), 0.05) << colour;  // √2 for white noise
  }
}

TEST(Synthetic, RejectsBadParameters) {
  SynthParams p;
  p.rate_hz = 30;
  EXPECT_THROW(SyntheticStream{p}, fovea::core::InputError);
  p.rate_hz = 120;
  p.noise_color = 1;
  EXPECT_THROW(SyntheticStream{p}, fovea::core::InputError);
}

// seconds=0 used to mean "endless": `fovea gaze info/plot/convert` walked it forever (convert
// wrote 700 MB in 15 s). A given length must be positive; leaving the key out stays endless.
TEST(Synthetic, ZeroSecondsIsAnErrorAndAGivenLengthEnds) {
  SourceOptions o;
  for (const char* uri : {"synthetic:1?seconds=0", "synthetic:1?seconds=-1", "hid-emulated:ms?seconds=0"}) {
    try {
      (void)open_sample_stream(uri, o);
      ADD_FAILURE() << uri << " was accepted";
    } catch (const fovea::core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("seconds="), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(uri), std::string::npos) << e.what();
    }
  }
  auto s = open_sample_stream("synthetic:1?seconds=0.5&rate=120", o);
  GazeSample g;
  int n = 0;
  while (s->next(g) && n < 1000) ++n;
  EXPECT_EQ(n, 60);
}
