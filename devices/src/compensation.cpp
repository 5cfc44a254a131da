#include "fovea/devices/compensation.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>
#include <vector>

#include "fovea/core/error.hpp"
#include "fovea/devices/filters.hpp"
#include "fovea/devices/foveation_gaze.hpp"
#include "fovea/devices/saccade_predict.hpp"

namespace fovea::devices {
namespace {

double nearest_rank(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0;
  const auto i = static_cast<std::size_t>(std::ceil(q * static_cast<double>(sorted.size())));
  return sorted[std::clamp<std::size_t>(i, 1, sorted.size()) - 1];
}

}  // namespace

void CompensationParams::validate() const {
  tracker.validate();
  if (latency_ns < 0 || latency_ns > 1'000'000'000) throw core::InputError("compensation: latency must be within 0..1 s");
  if (!(display_hz >= 10 && display_hz <= 1000)) throw core::InputError("compensation: display rate must be within 10..1000 Hz");
  if (horizon_ns < 0 || horizon_ns > 1'000'000'000) throw core::InputError("compensation: horizon must be within 0..1 s");
  if (after_saccade_ns <= 0) throw core::InputError("compensation: the post-saccade window must be positive");
  if (!(seconds > 0 && seconds <= 3600)) throw core::InputError("compensation: seconds must be within (0, 3600]");
}

FovealError measure_foveal_error(std::string_view truth_uri, PredictMode mode, const CompensationParams& p,
                                 const SourceOptions& opt) {
  p.validate();
  // The true eye is read as it is; the tracker's samples are predicted here, not by sources.
  SourceOptions raw = opt;
  raw.predict = PredictMode::None;
  TrackerParams tracker = p.tracker;
  tracker.host_clock = false;
  auto owned = std::make_unique<TrackerModel>(open_gaze_source(truth_uri, raw), tracker, raw);
  TrackerModel& model = *owned;
  FoveationGaze fovea(std::move(owned));
  const GazePredictor predictor(PredictParams{.mode = mode});
  SaccadeOnsetDetector onsets;

  FovealError r;
  r.mode = mode;
  std::deque<GazeSample> delivered;  // what the renderer has received, in order
  std::vector<double> post, all;
  // Stepping finer than the tracker's sample interval sees every delivery (they keep order).
  const core::TimeNs step = std::max<core::TimeNs>(1, std::min<core::TimeNs>(1'000'000, std::llround(2.5e8 / tracker.rate_hz)));
  core::TimeNs read_cursor = 0, truth_cursor = 0, last_truth = kNoSample, last_landing = 0;
  bool landed = false;
  for (std::int64_t k = 0;; ++k) {
    const core::TimeNs shown = std::llround(static_cast<double>(k) * 1e9 / p.display_hz);
    if (static_cast<double>(shown) > p.seconds * 1e9) break;
    // Each true sample once: the landing is the first slow interval after an onset.
    for (; truth_cursor <= shown; truth_cursor += step) {
      const GazeSample t = model.truth_at(truth_cursor);
      if (t.t_ns == kNoSample || t.t_ns <= last_truth) continue;
      last_truth = t.t_ns;
      const bool was_moving = onsets.in_saccade();
      onsets.add(t);
      if (was_moving && !onsets.in_saccade()) {
        ++r.saccades;
        landed = true;
        last_landing = t.t_ns;
      }
    }
    const core::TimeNs read = shown - p.latency_ns;
    for (; read_cursor <= read; read_cursor += step) {
      const GazeSample s = model.sample_at(read_cursor);
      if (s.t_ns == kNoSample || (!delivered.empty() && s.t_ns <= delivered.back().t_ns)) continue;
      delivered.push_back(s);
      while (delivered.size() > 2 && s.t_ns - delivered.front().t_ns > 500'000'000) delivered.pop_front();
    }
    if (delivered.empty() || read < 0) continue;
    const GazeSample truth = model.truth_at(shown);
    if (!truth.tracked()) continue;  // a blink of the true eye: nothing to foveate
    const GazeSample used = mode != PredictMode::None && p.horizon_ns > 0
                                ? predictor.predict(delivered, shown, p.horizon_ns)
                                : delivered.back();
    const double err = core::angle_deg(fovea.use(shown, used).combined.dir, truth.combined.dir);
    if (!std::isfinite(err)) continue;
    all.push_back(err);
    if (landed && shown - last_landing <= p.after_saccade_ns) post.push_back(err);
  }
  r.frames = all.size();
  r.post_frames = post.size();
  const auto mean = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
  };
  r.all_mean_deg = mean(all);
  r.mean_deg = mean(post);
  std::sort(post.begin(), post.end());
  r.p50_deg = nearest_rank(post, 0.50);
  r.p95_deg = nearest_rank(post, 0.95);
  r.max_deg = post.empty() ? 0 : post.back();
  r.over_2deg = post.empty() ? 0
                             : static_cast<double>(std::count_if(post.begin(), post.end(), [](double e) { return e > 2; })) /
                                   static_cast<double>(post.size());
  return r;
}

}  // namespace fovea::devices
