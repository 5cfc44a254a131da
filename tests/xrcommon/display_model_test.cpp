// The display model: vsync grid, presentation of late frames, photon times per scan-out.
#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/xrcommon/display_model.hpp"

namespace fovea::xrcommon {
namespace {

DisplayParams panel(double hz) {
  DisplayParams p;
  p.refresh_hz = hz;
  return p;
}

// A frame that finishes too late for its vsync is counted as missed and shown one period
// later; the previous frame stays on the panel meanwhile. On time: its own vsync.
TEST(DisplayModel, LateFrameIsMissedAndShownOnePeriodLater) {
  const DisplayModel m(panel(90), 1'000'000);
  const core::TimeNs p = m.period(), b = m.compositor_budget();
  EXPECT_EQ(p, 11'111'111);
  EXPECT_EQ(b, 3'000'000);
  const std::int64_t k = 10;
  const Presentation on_time = m.present(k, m.vsync_ns(k) - b);
  EXPECT_EQ(on_time.vsync, k);
  EXPECT_EQ(on_time.missed, 0);
  const Presentation late = m.present(k, m.vsync_ns(k) - b + 1);
  EXPECT_EQ(late.vsync, k + 1);
  EXPECT_EQ(late.missed, 1);
  EXPECT_EQ(late.vsync_ns, m.vsync_ns(k) + p);
  // Three and a half periods late: four vsyncs missed.
  const Presentation very = m.present(k, m.vsync_ns(k) + 3 * p + p / 2);
  EXPECT_EQ(very.missed, 4);
  // Never shown before it was submitted (plus the compositor's budget), for any submission.
  for (core::TimeNs sub = m.vsync_ns(k) - 3 * p; sub < m.vsync_ns(k) + 3 * p; sub += 999'983) {
    const Presentation s = m.present(k, sub);
    EXPECT_GE(s.vsync_ns, sub + b);
    EXPECT_GE(s.vsync, k);
    if (s.vsync > k) {
      EXPECT_LT(s.vsync_ns - p, sub + b);
    }
  }
}

TEST(DisplayModel, VsyncGridBeforeAndAfterTheEpoch) {
  const DisplayModel m(panel(100), 5'000'000);  // period 10 ms
  EXPECT_EQ(m.vsync_at_or_after(5'000'000), 0);
  EXPECT_EQ(m.vsync_at_or_after(5'000'001), 1);
  EXPECT_EQ(m.vsync_at_or_after(-4'999'999), -0);
  EXPECT_EQ(m.vsync_at_or_after(-5'000'000), -1);
  EXPECT_EQ(m.vsync_ns(-1), -5'000'000);
}

// Rolling scan-out: each region of each eye lights at its own time; the middle of the
// persistence is the photon time. Global: all rows at once.
TEST(DisplayModel, RollingScanOutPhotonTimesPerRegion) {
  DisplayParams p = panel(80);                // 12.5 ms
  p.scan_out = ScanOut::Rolling;
  p.scan_ns = 10'000'000;                     // top to bottom in 10 ms
  p.persistence_ns = 2'000'000;
  p.eye_offset_ns = {0, 500'000};             // the right eye's panel starts 0.5 ms later
  const DisplayModel m(p);
  const core::TimeNs v = m.vsync_ns(3);
  const PhotonTimes l = m.photons(v, core::Eye::Left), r = m.photons(v, core::Eye::Right);
  EXPECT_EQ(l.start, v + 1'000'000);
  EXPECT_EQ(l.mid, v + 5'000'000 + 1'000'000);
  EXPECT_EQ(l.end, v + 10'000'000 + 1'000'000);
  EXPECT_EQ(r.start, l.start + 500'000);
  EXPECT_EQ(r.mid, l.mid + 500'000);
  EXPECT_EQ(r.end, l.end + 500'000);
  EXPECT_EQ(m.photon_ns(v, core::Eye::Left, 0.25), v + 2'500'000 + 1'000'000);
  // No scan_ns: the scan-out takes the whole period.
  p.scan_ns = -1;
  EXPECT_EQ(DisplayModel(p).photons(0, core::Eye::Left).end, 12'500'000 + 1'000'000);
  p.scan_out = ScanOut::Global;
  const PhotonTimes g = DisplayModel(p).photons(v, core::Eye::Left);
  EXPECT_EQ(g.start, g.end);
  EXPECT_EQ(g.mid, v + 1'000'000);
}

TEST(DisplayModel, BadParametersAreRefused) {
  DisplayParams p = panel(0);
  EXPECT_THROW(DisplayModel{p}, core::InputError);
  p = panel(90);
  p.persistence_ns = 20'000'000;  // longer than a period
  EXPECT_THROW(DisplayModel{p}, core::InputError);
  p = panel(90);
  p.scan_ns = 12'000'000;
  EXPECT_THROW(DisplayModel{p}, core::InputError);
  p = panel(90);
  p.eye_offset_ns = {0, -1};
  EXPECT_THROW(DisplayModel{p}, core::InputError);
  EXPECT_THROW(parse_scan_out("diagonal"), core::InputError);
  EXPECT_EQ(parse_scan_out("rolling"), ScanOut::Rolling);
}

// The pacer's display decision is the model's: a frame submitted late for its slot is shown
// at the first later vsync, on the slot's grid.
TEST(FramePacer, DisplaysThroughTheModel) {
  FramePacer c(panel(70));
  const FrameSlot s = c.next(2'000'000'000);
  EXPECT_EQ(c.model().vsync_ns(s.vsync), s.display_ns);
  const Presentation pr = c.model().present(s.vsync, s.display_ns);
  EXPECT_EQ(c.displayed(s.display_ns, s.display_ns), pr.vsync_ns);
  EXPECT_EQ(pr.missed, 1);
}

}  // namespace
}  // namespace fovea::xrcommon
