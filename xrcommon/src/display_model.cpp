#include "fovea/xrcommon/display_model.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "fovea/core/error.hpp"

namespace fovea::xrcommon {

ScanOut parse_scan_out(std::string_view s) {
  if (s == "global") return ScanOut::Global;
  if (s == "rolling") return ScanOut::Rolling;
  throw core::InputError("scan-out \"" + std::string(s) + "\": expected global or rolling");
}

const char* scan_out_name(ScanOut s) { return s == ScanOut::Global ? "global" : "rolling"; }

void DisplayParams::validate() const {
  if (!(refresh_hz >= 1 && refresh_hz <= 2000))
    throw core::InputError("display refresh rate " + std::to_string(refresh_hz) + " Hz: expected 1..2000 Hz");
  const auto period = static_cast<core::TimeNs>(std::llround(1e9 / refresh_hz));
  if (persistence_ns < 0 || persistence_ns > period)
    throw core::InputError("display persistence " + std::to_string(persistence_ns) + " ns: expected 0..one period (" +
                           std::to_string(period) + " ns)");
  if (scan_ns > period)
    throw core::InputError("rolling scan-out of " + std::to_string(scan_ns) + " ns: longer than one period (" +
                           std::to_string(period) + " ns)");
  for (core::TimeNs o : eye_offset_ns)
    if (o < 0 || o >= period) throw core::InputError("eye scan-out offset " + std::to_string(o) + " ns: expected 0..period");
}

DisplayModel::DisplayModel(const DisplayParams& p, core::TimeNs epoch_ns) : p_(p), epoch_(epoch_ns) {
  p_.validate();
  period_ = static_cast<core::TimeNs>(std::llround(1e9 / p_.refresh_hz));
  // Compositor budget: 20 % of the frame, at least 3 ms (a common open-loop pacing choice).
  budget_ = p_.compositor_ns >= 0 ? p_.compositor_ns : std::max<core::TimeNs>(period_ / 5, core::ms_to_ns(3.0));
  scan_ = p_.scan_out == ScanOut::Global ? 0 : (p_.scan_ns >= 0 ? p_.scan_ns : period_);
}

std::int64_t DisplayModel::vsync_at_or_after(core::TimeNs t) const {
  const core::TimeNs d = t - epoch_;
  // Floor division for times before the epoch too.
  const std::int64_t below = d >= 0 ? d / period_ : -((-d + period_ - 1) / period_);
  return vsync_ns(below) >= t ? below : below + 1;
}

Presentation DisplayModel::present(std::int64_t target, core::TimeNs submitted_ns) const {
  const std::int64_t k = std::max(target, vsync_at_or_after(submitted_ns + budget_));
  return {k, vsync_ns(k), k - target};
}

core::TimeNs DisplayModel::photon_ns(core::TimeNs vsync, core::Eye e, double v) const {
  const double row = std::clamp(v, 0.0, 1.0);
  return vsync + p_.eye_offset_ns[e == core::Eye::Left ? 0 : 1] + std::llround(row * double(scan_)) +
         p_.persistence_ns / 2;
}

PhotonTimes DisplayModel::photons(core::TimeNs vsync, core::Eye e) const {
  return {photon_ns(vsync, e, 0.0), photon_ns(vsync, e, 0.5), photon_ns(vsync, e, 1.0)};
}

namespace {
DisplayParams refresh_only(double hz) {
  DisplayParams p;
  p.refresh_hz = hz;
  return p;
}
}  // namespace

FramePacer::FramePacer(const DisplayParams& p, Pacing pacing) : model_(p), pacing_(pacing) {}
FramePacer::FramePacer(double refresh_hz, Pacing pacing) : FramePacer(refresh_only(refresh_hz), pacing) {}

FrameSlot FramePacer::next(core::TimeNs now) {
  const core::TimeNs lead = period() + compositor_budget();  // wake time before the vsync
  if (!started_) {
    model_ = DisplayModel(model_.params(), now + lead);
    started_ = true;
  }
  std::int64_t k = next_vsync_;
  if (pacing_ == Pacing::Realtime && model_.vsync_ns(k) - lead < now) {
    // Late: the first vsync whose wake time is not yet past.
    k = model_.vsync_at_or_after(now + lead);
  }
  FrameSlot s;
  s.index = next_index_++;
  s.vsync = k;
  s.missed = k - next_vsync_;
  s.display_ns = model_.vsync_ns(k);
  s.wake_ns = s.display_ns - lead;
  next_vsync_ = k + 1;
  return s;
}

void FramePacer::reslot(FrameSlot& s, core::TimeNs now) {
  if (pacing_ != Pacing::Realtime) return;
  const std::int64_t skip = model_.present(s.vsync, now).missed;
  s.vsync += skip;
  s.missed += skip;
  s.display_ns += skip * period();
  s.wake_ns += skip * period();
  next_vsync_ = s.vsync + 1;
}

core::TimeNs FramePacer::displayed(core::TimeNs display_ns, core::TimeNs submitted_ns) const {
  // On the grid through display_ns (a slot's display time, or any vsync before the start).
  return DisplayModel(model_.params(), display_ns).present(0, submitted_ns).vsync_ns;
}

}  // namespace fovea::xrcommon
