#pragma once
// The display model shared by the simulated runtime and `fovea latency` (docs/latency.md):
// a panel refreshing every period from an epoch, scanned out globally or rolling per eye,
// each row lit for the persistence time; a frame is shown at the first vsync that leaves the
// compositor its budget after the frame's submission, never earlier, and a frame that misses
// its vsync leaves the previous one on the panel (counted as missed). FramePacer adds the
// frame pacing of xrWaitFrame on top. Pure functions of the times given: virtual time
// (tests, `fovea latency`) and the host monotonic clock (the runtime) alike, int64 ns.
#include <array>
#include <cstdint>
#include <string_view>

#include "fovea/core/clock.hpp"
#include "fovea/core/display.hpp"

namespace fovea::xrcommon {

enum class ScanOut { Global, Rolling };
ScanOut parse_scan_out(std::string_view s);  // "global" | "rolling"; throws core::InputError
const char* scan_out_name(ScanOut s);

struct DisplayParams {
  double refresh_hz = 90;
  // Global: every row of an eye lights at once. Rolling: row v (0 top .. 1 bottom) lights
  // v·scan_ns after the eye's scan-out start, as an LCD/OLED driven line by line.
  ScanOut scan_out = ScanOut::Global;
  core::TimeNs scan_ns = -1;         // rolling: first to last row; < 0: one refresh period
  core::TimeNs persistence_ns = 0;   // how long a row stays lit (low persistence: ~2 ms)
  core::TimeNs compositor_ns = -1;   // the compositor's budget before a vsync; < 0: max(period/5, 3 ms)
  // Scan-out start of each eye after the vsync (left, right): {0, 0} for two panels scanned
  // together; {0, period/2} for one panel scanned across both eyes.
  std::array<core::TimeNs, 2> eye_offset_ns{0, 0};
  void validate() const;  // throws core::InputError naming the bad field
};

// When the rows of one eye emit light, each at the middle of its persistence: the first
// (top) row, the middle row and the last (bottom) row. Equal for a global scan-out.
struct PhotonTimes {
  core::TimeNs start = 0, mid = 0, end = 0;
};

struct Presentation {
  std::int64_t vsync = 0;       // the vsync that shows the frame
  core::TimeNs vsync_ns = 0;
  std::int64_t missed = 0;      // vsyncs after the target at which the previous frame stayed
};

class DisplayModel {
 public:
  explicit DisplayModel(const DisplayParams& p = {}, core::TimeNs epoch_ns = 0);
  const DisplayParams& params() const { return p_; }
  core::TimeNs period() const { return period_; }
  core::TimeNs compositor_budget() const { return budget_; }
  core::TimeNs epoch() const { return epoch_; }
  core::TimeNs vsync_ns(std::int64_t k) const { return epoch_ + k * period_; }
  // The first vsync at or after t.
  std::int64_t vsync_at_or_after(core::TimeNs t) const;
  // A frame meant for vsync `target` and submitted at `submitted_ns`: shown at the first
  // vsync ≥ target with the compositor budget left after the submission.
  Presentation present(std::int64_t target, core::TimeNs submitted_ns) const;
  // Light from the rows at height v ∈ [0, 1] of eye e for the frame scanned out at vsync_ns.
  core::TimeNs photon_ns(core::TimeNs vsync_ns, core::Eye e, double v) const;
  PhotonTimes photons(core::TimeNs vsync_ns, core::Eye e) const;

 private:
  DisplayParams p_;
  core::TimeNs period_, budget_, scan_, epoch_;
};

// Frame pacing of xrWaitFrame on the display model.
//
// Realtime (the default): each frame is given the next vsync the application can still
// make. A frame whose nominal vsync's wake time has already passed when xrWaitFrame is
// called (the previous frame was slow) moves to the first later vsync whose wake time is not
// past, so the predicted display time is never in the past and xrWaitFrame throttles again
// from there. Lockstep: frame n is always shown at t0 + n·period and a late application is
// never made to skip vsyncs; head pose, gaze and hence the application's content are then a
// function of the frame index, so runs are reproducible, at the cost of stale predictions
// for a slow application.
enum class Pacing { Realtime, Lockstep };

struct FrameSlot {
  std::int64_t index = 0;       // frame number (0, 1, 2, … in xrWaitFrame order)
  std::int64_t vsync = 0;       // vsync number of the predicted display time
  std::int64_t missed = 0;      // vsyncs skipped because the application was late
  core::TimeNs display_ns = 0;  // predicted display time: the vsync's time
  core::TimeNs wake_ns = 0;     // when xrWaitFrame returns: one period plus the compositor budget earlier
};

class FramePacer {
 public:
  explicit FramePacer(const DisplayParams& p, Pacing pacing = Pacing::Realtime);
  explicit FramePacer(double refresh_hz, Pacing pacing = Pacing::Realtime);
  core::TimeNs period() const { return model_.period(); }
  core::TimeNs compositor_budget() const { return model_.compositor_budget(); }
  Pacing pacing() const { return pacing_; }
  // The vsync grid and photon times; its epoch is fixed by the first next().
  const DisplayModel& model() const { return model_; }
  // The next frame's slot; `now` is the time of the xrWaitFrame call. The first call fixes t0
  // so that the first frame's wake time is `now`. Realtime: wake_ns >= now, hence
  // display_ns > now.
  FrameSlot next(core::TimeNs now);
  // When a frame predicted for `display_ns` (a vsync) and submitted at `submitted_ns` is
  // shown: DisplayModel::present. Never earlier than the submission.
  core::TimeNs displayed(core::TimeNs display_ns, core::TimeNs submitted_ns) const;
  // Realtime: for the slot just returned by next(), when xrWaitFrame wakes at `now` so late
  // (a loaded host) that less than the compositor budget is left before its vsync, moves it
  // to the first vsync that leaves it, so the prediction is still ahead when the call returns.
  void reslot(FrameSlot& s, core::TimeNs now);
  core::TimeNs epoch() const { return model_.epoch(); }
  bool started() const { return started_; }

 private:
  DisplayModel model_;
  Pacing pacing_;
  std::int64_t next_index_ = 0;
  std::int64_t next_vsync_ = 0;
  bool started_ = false;
};

}  // namespace fovea::xrcommon
