// The runtime's device models: the display clock and the head motion (scripted and files).
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include "display_clock.hpp"
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

}  // namespace
}  // namespace fovea::runtime
