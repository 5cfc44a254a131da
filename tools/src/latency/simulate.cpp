#include "simulate.hpp"

#include <algorithm>
#include <cmath>

#include "fovea/core/error.hpp"
#include "fovea/core/grid_hold.hpp"
#include "fovea/core/view.hpp"
#include "fovea/devices/ivt.hpp"

namespace fovea::latency {

namespace {

// Saccades of the true eye: I-VT over its samples, each classified once at its own time.
std::vector<Saccade> find_saccades(devices::TrackerModel& tracker, core::TimeNs end_ns) {
  std::vector<Saccade> out;
  devices::IvtClassifier ivt;
  core::TimeNs last = devices::kNoSample;
  bool in_saccade = false;
  glm::dvec3 start_dir{0, 0, -1};
  for (core::TimeNs t = 0; t <= end_ns; t += 1'000'000) {
    const devices::GazeSample s = tracker.truth_at(t);
    if (s.t_ns == devices::kNoSample || s.t_ns == last) continue;
    last = s.t_ns;
    const bool saccade = ivt.classify(s) == devices::Motion::Saccade;
    if (saccade && !in_saccade) {
      out.push_back({s.t_ns, s.t_ns, 0});
      start_dir = ivt.window_start_dir();  // the velocity window lags the eye: it started there
    } else if (!saccade && in_saccade) {
      out.back().offset_ns = s.t_ns;
      if (s.tracked()) out.back().amplitude_deg = core::angle_deg(start_dir, s.combined.dir);
    }
    in_saccade = saccade;
  }
  if (in_saccade) out.pop_back();  // unfinished at the end
  return out;
}

std::optional<glm::dvec3> true_dir(devices::TrackerModel& tracker, core::TimeNs t, core::Eye e) {
  const devices::GazeSample s = tracker.truth_at(t);
  if (s.t_ns == devices::kNoSample || !s.eye(e).tracked()) return std::nullopt;
  return s.eye(e).dir;
}

}  // namespace

std::unique_ptr<devices::TrackerModel> open_tracker(const std::string& gaze_uri, const TrackerChoice& choice,
                                                    const devices::SourceOptions& opt) {
  const auto q = gaze_uri.find('?');
  if (q != std::string::npos && gaze_uri.find("tracker", q) != std::string::npos)
    throw core::InputError("--gaze \"" + gaze_uri +
                           "\": give the tracker model with --tracker, --tracker-delay, --jitter and --rate, "
                           "not as URI keys");
  devices::TrackerParams p = devices::tracker_preset(choice.preset);
  if (choice.delay_ns) p.delay_ns = *choice.delay_ns;
  if (choice.jitter_ns) p.jitter_ns = *choice.jitter_ns;
  if (choice.rate_hz) p.rate_hz = *choice.rate_hz;
  p.delay_ns += choice.inject_ns;
  p.validate();
  // The URI's gaze is the true eye, read as it is (no prediction).
  devices::SourceOptions truth = opt;
  truth.horizon_ns = 0;
  std::unique_ptr<devices::GazeSource> eye = devices::open_gaze_source(gaze_uri, truth);
  if (eye->is_live()) throw core::InputError("--gaze \"" + gaze_uri + "\": a live source has no ground truth; give a recording or synthetic gaze");
  return std::make_unique<devices::TrackerModel>(std::move(eye), p, opt);
}

Simulation simulate(devices::TrackerModel& tracker, const Scenario& sc, const RenderFn& render) {
  Simulation sim;
  // The application foveates through the one gaze path every program uses; it does not own
  // the tracker, whose truth the harness keeps reading.
  struct Borrowed final : devices::GazeSource {
    devices::TrackerModel& t;
    explicit Borrowed(devices::TrackerModel& m) : t(m) {}
    devices::GazeSample latest() override { return t.latest(); }
    devices::GazeSample sample_at(core::TimeNs when) override { return t.sample_at(when); }
    devices::GazeSample read_at(core::TimeNs read, core::TimeNs target) override { return t.read_at(read, target); }
    devices::GazeSample truth_at(core::TimeNs when) override { return t.truth_at(when); }
    bool is_live() const override { return false; }
    std::string describe() const override { return t.describe(); }
  };
  devices::FoveationGaze gaze(std::make_unique<Borrowed>(tracker));
  gaze.set_epoch(0);
  xrcommon::FramePacer pacer(sc.display);
  std::array<core::GridHold, 3> hold{core::GridHold(sc.hold_deg), core::GridHold(sc.hold_deg),
                                     core::GridHold(sc.hold_deg)};  // left, right, combined
  core::TimeNs now = 0;
  for (std::int64_t f = 0;; ++f) {
    xrcommon::FrameSlot slot = pacer.next(now);
    const core::TimeNs wake = std::max(now, slot.wake_ns);  // xrWaitFrame returns
    if (wake >= sc.duration_ns) break;
    pacer.reslot(slot, wake);
    // What the tracker had delivered at the wake, predicted to the display time when the
    // tracker's source predicts (--predict).
    const devices::FoveaGaze g = gaze.read(wake, slot.display_ns);
    FrameWork work = render(f, g);
    // Each eye's grid as the frame pipeline lays it out (held through a fixational drift).
    const std::array<glm::dvec3, 2> dirs{hold[0].place(g.left.dir), hold[1].place(g.right.dir)};
    const core::TimeNs submit = wake + work.cost_ns;
    const xrcommon::DisplayModel& m = pacer.model();
    const xrcommon::Presentation shown = m.present(slot.vsync, submit);

    xrcommon::TimingRecord r;
    r.source = "latency";
    r.clock = xrcommon::TimeBase::Virtual;
    r.frame = f;
    r.gaze_valid = g.combined.tracked();
    if (g.has_sample) {
      r.gaze_sample_ns = g.sample_ns;
      r.gaze_device_ns = g.device_ns;
      r.gaze_receive_ns = g.receive_ns;
    }
    r.gaze_read_ns = wake;
    r.head_pose_ns = wake;  // the application locates its views when it wakes,
    r.head_pose_target_ns = slot.display_ns;  // for the predicted display time
    r.predicted_display_ns = slot.display_ns;
    r.set_frame_calls(now, wake, wake, submit, submit);  // the modelled calls return at once
    r.submit_ns = submit;
    r.vsync_ns = shown.vsync_ns;
    r.missed_vsyncs = slot.missed + shown.missed;
    const std::array<xrcommon::PhotonTimes, 2> ph{m.photons(shown.vsync_ns, core::Eye::Left),
                                                  m.photons(shown.vsync_ns, core::Eye::Right)};
    r.photon_ns = ph;
    r.cpu_ms = std::move(work.cpu_ms);
    r.gpu_ms = std::move(work.gpu_ms);
    r.fovea_dir = hold[2].place(g.combined.dir);
    const devices::GazeSample truth = tracker.truth_at(ph[0].mid);
    if (truth.t_ns != devices::kNoSample && truth.tracked()) r.true_gaze_dir = truth.combined.dir;
    sim.records.push_back(std::move(r));
    FrameTruth ft;
    ft.fovea = dirs;
    for (core::Eye e : {core::Eye::Left, core::Eye::Right})
      ft.truth[std::size_t(e)] = true_dir(tracker, ph[std::size_t(e)].mid, e);
    sim.frames.push_back(ft);
    now = submit;  // the application calls xrWaitFrame again at once
  }
  if (sim.records.empty()) return sim;

  // The panel vsync by vsync: the newest frame presented by then stays on it.
  const xrcommon::DisplayModel& m = pacer.model();
  std::size_t i = 0;
  const std::int64_t first = m.vsync_at_or_after(*sim.records.front().vsync_ns);
  const std::int64_t last = m.vsync_at_or_after(*sim.records.back().vsync_ns);
  for (std::int64_t k = first; k <= last; ++k) {
    while (i + 1 < sim.records.size() && *sim.records[i + 1].vsync_ns <= m.vsync_ns(k)) ++i;
    Shown s;
    s.vsync = k;
    s.vsync_ns = m.vsync_ns(k);
    s.photon_ns = m.photon_ns(m.vsync_ns(k), core::Eye::Left, 0.5);
    s.frame = sim.records[i].frame;
    if (auto t = true_dir(tracker, s.photon_ns, core::Eye::Left)) s.error_deg = core::angle_deg(sim.frames[i].fovea[0], *t);
    sim.shown.push_back(s);
  }
  sim.saccades = find_saccades(tracker, m.vsync_ns(last));
  return sim;
}

std::vector<double> recovery_ms(const Simulation& sim, double threshold_deg, double min_amplitude_deg) {
  std::vector<double> out;
  for (const Saccade& s : sim.saccades) {
    if (s.amplitude_deg < min_amplitude_deg) continue;
    auto it = std::find_if(sim.shown.begin(), sim.shown.end(), [&](const Shown& v) {
      return v.photon_ns >= s.offset_ns && v.error_deg && *v.error_deg < threshold_deg;
    });
    if (it == sim.shown.end()) continue;  // not recovered before the end
    out.push_back(core::ns_to_ms(it->photon_ns - s.offset_ns));
  }
  return out;
}

std::vector<double> post_saccade_errors(const Simulation& sim, core::TimeNs window_ns, double min_amplitude_deg) {
  std::vector<double> out;
  for (const Shown& v : sim.shown) {
    if (!v.error_deg) continue;
    const bool after = std::any_of(sim.saccades.begin(), sim.saccades.end(), [&](const Saccade& s) {
      return s.amplitude_deg >= min_amplitude_deg && v.photon_ns >= s.offset_ns && v.photon_ns - s.offset_ns <= window_ns;
    });
    if (after) out.push_back(*v.error_deg);
  }
  return out;
}

}  // namespace fovea::latency
