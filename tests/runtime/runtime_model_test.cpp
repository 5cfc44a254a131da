// The runtime's device models: the display clock, the head motion (scripted and files) and
// the eye tracker's reads.
#include <cmath>
#include <fstream>
#include <string>

#include <glm/geometric.hpp>

#include <gtest/gtest.h>

#include "display_clock.hpp"
#include "gaze.hpp"
#include "fovea/core/error.hpp"
#include "head_motion.hpp"
#include "xr_process.hpp"

namespace fovea::runtime {
namespace {

TEST(DisplayClock, LockstepSlots) {
  DisplayClock c(70, Pacing::Lockstep);
  EXPECT_EQ(c.period(), 14285714);
  EXPECT_EQ(c.compositor_budget(), 3'000'000);  // 20 % of 14.3 ms is below the 3 ms floor
  const FrameSlot a = c.next(1'000'000'000);
  EXPECT_EQ(a.index, 0);
  EXPECT_EQ(a.wake_ns, 1'000'000'000);  // the first frame wakes at once
  EXPECT_EQ(a.display_ns - a.wake_ns, c.period() + c.compositor_budget());
  // Called late (5 periods later): the next slot is still the next vsync, not skipped.
  const FrameSlot b = c.next(a.display_ns + 5 * c.period());
  EXPECT_EQ(b.index, 1);
  EXPECT_EQ(b.display_ns, a.display_ns + c.period());
  EXPECT_EQ(DisplayClock(90).compositor_budget(), 3'000'000);
  EXPECT_EQ(DisplayClock(30).compositor_budget(), DisplayClock(30).period() / 5);
}

// Realtime pacing on a deterministic clock: an on-time application gets consecutive vsyncs;
// after a slow frame the prediction is the first vsync whose wake time is still ahead (never
// in the past), and the following frames are throttled one period apart again.
TEST(DisplayClock, RealtimeSkipsMissedVsyncsAndThrottlesAgain) {
  DisplayClock c(70);
  EXPECT_EQ(c.pacing(), Pacing::Realtime);
  const core::TimeNs p = c.period();
  const FrameSlot a = c.next(1'000'000'000);
  EXPECT_EQ(a.wake_ns, 1'000'000'000);
  const FrameSlot b = c.next(a.wake_ns + p / 2);  // on time: the next vsync
  EXPECT_EQ(b.display_ns, a.display_ns + p);
  EXPECT_EQ(b.missed, 0);
  // A slow frame: xrWaitFrame called 5.5 periods after b's wake time.
  const core::TimeNs now = b.wake_ns + 5 * p + p / 2;
  const FrameSlot s = c.next(now);
  EXPECT_EQ(s.index, 2);
  EXPECT_GE(s.wake_ns, now);
  EXPECT_LT(s.wake_ns - now, p);  // the first such vsync, not a later one
  EXPECT_GT(s.display_ns, now);
  EXPECT_EQ(s.missed, 5);
  EXPECT_EQ(s.vsync, b.vsync + 6);
  EXPECT_EQ((s.display_ns - a.display_ns) % p, 0);  // on the vsync grid
  // Fast frames after it: throttled, one vsync each.
  core::TimeNs t = s.wake_ns;
  core::TimeNs last = s.display_ns;
  for (int i = 0; i < 5; ++i) {
    const FrameSlot f = c.next(t + 1000);
    EXPECT_EQ(f.display_ns, last + p);
    EXPECT_EQ(f.missed, 0);
    EXPECT_GT(f.wake_ns, t);
    last = f.display_ns;
    t = f.wake_ns;
  }
  // Exactly on the wake time is on time.
  const FrameSlot g = c.next(last - p - c.compositor_budget() + p);
  EXPECT_EQ(g.missed, 0);
  // Woken on time: the slot stays. Woken after its vsync (a descheduled thread): it moves to
  // the first vsync that leaves the compositor budget, and the next slot follows it.
  FrameSlot h = c.next(g.wake_ns);
  const FrameSlot h0 = h;
  c.reslot(h, h.wake_ns + 1000);
  EXPECT_EQ(h.display_ns, h0.display_ns);
  const core::TimeNs woke = h.display_ns + 2 * p + p / 3;
  c.reslot(h, woke);
  EXPECT_GE(h.display_ns, woke + c.compositor_budget());
  EXPECT_LT(h.display_ns - p, woke + c.compositor_budget());
  EXPECT_EQ(h.missed, h0.missed + 3);
  EXPECT_EQ(c.next(woke).display_ns, h.display_ns + p);
}

// A frame is displayed at its predicted vsync when submitted with the compositor budget to
// spare, else at the first later vsync that leaves it; never before its submission.
TEST(DisplayClock, DisplayedNeverBeforeSubmission) {
  const DisplayClock c(70);
  const core::TimeNs p = c.period(), budget = c.compositor_budget(), d = 10'000'000'000;
  EXPECT_EQ(c.displayed(d, d - budget), d);
  EXPECT_EQ(c.displayed(d, d - budget + 1), d + p);
  EXPECT_EQ(c.displayed(d, d + 3 * p), d + 4 * p);
  for (core::TimeNs sub = d - 2 * p; sub < d + 5 * p; sub += 777'777) {
    const core::TimeNs shown = c.displayed(d, sub);
    EXPECT_GE(shown, sub + budget);
    if (shown > d) {
      EXPECT_LT(shown - p, sub + budget);  // the first vsync that makes it
    }
    EXPECT_EQ((shown - d) % p, 0);
  }
}

TEST(HeadMotion, ScriptedIsSmoothAndStartsAtIdentity) {
  const HeadMotion h = HeadMotion::scripted();
  const core::Pose p0 = h.at(0);
  EXPECT_NEAR(glm::angle(p0.orientation), 0.0, 1e-12);
  EXPECT_NEAR(glm::length(p0.position), 0.0, 1e-12);
  // Slow: under 20°/s anywhere (yaw 10° amplitude over 8 s peaks at 7.9°/s).
  for (int ms = 0; ms < 20000; ms += 11) {
    const core::Pose a = h.at(core::ms_to_ns(ms)), b = h.at(core::ms_to_ns(ms + 1));
    const double deg_per_s = glm::degrees(glm::angle(glm::inverse(a.orientation) * b.orientation)) * 1000.0;
    ASSERT_LT(deg_per_s, 20.0) << ms;
  }
}

TEST(HeadMotion, FileInterpolatesAndHolds) {
  test::TempDir dir("head");
  const std::string path = dir.path() + "/head.txt";
  std::ofstream(path) << "# t px py pz qx qy qz qw\n"
                         "0 0 0 0 0 0 0 1\n"
                         "\n"
                         "1 0.2 0 0 0 0.7071067811865476 0 0.7071067811865476  # 90 degrees yaw\n";
  const HeadMotion h = HeadMotion::from_file(path);
  EXPECT_NEAR(h.at(core::ms_to_ns(500)).position.x, 0.1, 1e-12);
  EXPECT_NEAR(glm::degrees(glm::angle(h.at(core::ms_to_ns(500)).orientation)), 45.0, 1e-9);
  EXPECT_NEAR(h.at(core::ms_to_ns(5000)).position.x, 0.2, 1e-12);  // held after the end
  EXPECT_NEAR(h.at(-core::ms_to_ns(5000)).position.x, 0.0, 1e-12);
}

TEST(HeadMotion, BadFilesNameTheLine) {
  test::TempDir dir("head_bad");
  const std::string path = dir.path() + "/bad.txt";
  auto expect_error = [&](const std::string& text, const std::string& what) {
    std::ofstream(path) << text;
    try {
      HeadMotion::from_file(path);
      ADD_FAILURE() << "no error for: " << text;
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_error("0 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0\n", ":2: expected");
  expect_error("0 0 0 0 0 0 0 1 7\n", ":1: expected");
  expect_error("0 0 0 0 0 0 0 2\n", ":1: quaternion is not unit length");
  expect_error("1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n", ":2: time must increase");
  expect_error("0 nan 0 0 0 0 0 1\n", ":1: \"nan\" is not a finite number");
  expect_error("# only a comment\n", "no head pose samples");
  EXPECT_THROW(HeadMotion::from_file(dir.path() + "/missing.txt"), core::InputError);
  EXPECT_THROW(HeadMotion::from_spec(dir.path() + "/missing.txt"), core::InputError);
}

// The tracker's k-th sample time at `rate` (the synthetic stream's and the tracker model's grid).
core::TimeNs sample_time(std::int64_t k, double rate) { return std::llround(double(k) * 1e9 / rate); }

// The runtime reads the gaze honestly: at a read time between samples it gets the newest
// sample delivered by then — device time <= read time - tracker delay — never one measured
// later, whatever later time (the display time) it reads for; received `delay` after it was
// measured; with and without prediction, at 60, 120, 250 and 1000 Hz. (The runtime used to
// read at the display time: a sample from the future.)
TEST(GazeRead, NewestSampleDeliveredByTheReadTime) {
  const core::DisplayPreset display = core::load_display("small");
  const core::TimeNs epoch = 3'000'000'000;  // host time of the source's t = 0
  for (const double rate : {60.0, 120.0, 250.0, 1000.0})
    for (const core::TimeNs delay : {core::TimeNs(0), core::TimeNs(20'000'000)})
      for (const std::string predict : {"none", "linear"}) {
        const std::string r = std::to_string(int(rate));
        // Without a tracker model the synthetic stream is the tracker; with one, the model
        // samples the 1 kHz true eye at its own rate and delivers after its delay.
        const std::string uri = delay == 0 ? "synthetic:3?noise=0&dropouts=0&predict=" + predict + "&rate=" + r
                                           : "synthetic:3?noise=0&dropouts=0&rate=1000&predict=" + predict +
                                                 "&tracker=ideal&tracker_jitter=0&tracker_delay=20ms&tracker_rate=" + r;
        SCOPED_TRACE(uri);
        GazeTracker tracker(uri, display);
        for (int i = 0; i < 60; ++i) {
          const core::TimeNs read = epoch + 100'000'000 + core::TimeNs(i) * 7'300'001;  // between samples
          const core::TimeNs target = read + 30'000'000;  // e.g. the frame's display time
          const GazeSample g = tracker.read(read, target, epoch);
          std::int64_t k = 0;
          while (sample_time(k + 1, rate) <= read - epoch - delay) ++k;
          EXPECT_EQ(g.sample_ns, epoch + sample_time(k, rate)) << i;
          EXPECT_LE(g.sample_ns, read - delay);
          EXPECT_EQ(g.receive_ns, g.sample_ns + delay);
          EXPECT_EQ(g.read_ns, read);
        }
        // A time before the read: the samples measured by that time.
        const GazeSample past = tracker.read(epoch + 500'000'000, epoch + 200'000'000, epoch);
        EXPECT_LE(past.sample_ns, epoch + 200'000'000 - delay);
        EXPECT_EQ(past.read_ns, epoch + 200'000'000);
      }
}

// Prediction extrapolates from the delivered samples only: two recordings equal up to the
// read time and different after it give the same predicted gaze; the prediction moves the
// direction (a 10 deg/s pursuit) ahead of the newest sample towards the target time.
TEST(GazeRead, PredictionUsesDeliveredSamplesOnly) {
  test::TempDir dir("gaze_read");
  const auto write = [&](const std::string& name, bool jump) {
    const std::string file = dir.path() + "/" + name;
    std::ofstream out(file);
    out << "t_ns,eye,dir_x,dir_y,dir_z,confidence,flags\n";
    for (int i = 0; i <= 100; ++i) {  // 100 Hz
      const double yaw_deg = i <= 50 || !jump ? 0.1 * i : 25.0;  // 10 deg/s, or a jump after 0.5 s
      const double yaw = yaw_deg * M_PI / 180;
      out << std::int64_t(i) * 10'000'000 << ",combined," << std::sin(yaw) << ",0," << -std::cos(yaw) << ",1,1\n";
    }
    return file;
  };
  const std::string smooth = write("smooth.csv", false), jump = write("jump.csv", true);
  const core::DisplayPreset display = core::load_display("small");
  const core::TimeNs epoch = 1'000'000'000, read = epoch + 503'000'000, target = read + 17'000'000;
  const auto yaw_deg = [](const GazeSample& g) { return std::atan2(g.dir.x, -g.dir.z) * 180 / M_PI; };
  GazeTracker a("replay:" + smooth + "?predict=linear", display), b("replay:" + jump + "?predict=linear", display);
  const GazeSample ga = a.read(read, target, epoch), gb = b.read(read, target, epoch);
  EXPECT_EQ(ga.sample_ns, epoch + 500'000'000);
  EXPECT_EQ(gb.sample_ns, epoch + 500'000'000);
  ASSERT_TRUE(ga.valid && gb.valid);
  EXPECT_NEAR(yaw_deg(ga), yaw_deg(gb), 1e-6);
  EXPECT_NEAR(yaw_deg(ga), 5.0 + 10.0 * 0.020, 0.02);  // the newest sample (5 deg) 20 ms ahead
  GazeTracker held("replay:" + smooth + "?predict=none", display);
  EXPECT_NEAR(yaw_deg(held.read(read, target, epoch)), 5.0, 1e-4);
  // The ground truth is the recording at the time asked for, whatever was delivered.
  const auto truth = b.truth_at(epoch + 700'000'000, epoch);
  ASSERT_TRUE(truth);
  EXPECT_NEAR(std::atan2(truth->x, -truth->z) * 180 / M_PI, 25.0, 1e-4);
  GazeTracker live("hid-emulated:ms?seed=1&seconds=0.1", display);
  EXPECT_FALSE(live.truth_at(epoch, epoch));  // a live tracker has no ground truth
}

}  // namespace
}  // namespace fovea::runtime
