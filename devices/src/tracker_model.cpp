#include "fovea/devices/tracker_model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>

#include "fovea/core/duration.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/view.hpp"
#include "source_uri.hpp"

namespace fovea::devices {

void TrackerParams::validate() const {
  const auto bad = [&](const std::string& what) { return core::InputError("tracker model \"" + name + "\": " + what); };
  if (!std::isfinite(rate_hz) || rate_hz < 10 || rate_hz > 2000) throw bad("rate must be in [10, 2000] Hz");
  if (delay_ns < 0 || jitter_ns < 0 || burst_ns < 0) throw bad("delay, jitter and burst length must be >= 0");
  if (delay_ns > 10'000'000'000 || jitter_ns > 1'000'000'000 || burst_ns > 10'000'000'000)
    throw bad("delay and burst length must be <= 10 s, jitter <= 1 s");
  if (!std::isfinite(noise_deg) || noise_deg < 0 || noise_deg > 10) throw bad("noise must be in [0, 10] degrees RMS");
  if (!std::isfinite(dropout) || dropout < 0 || dropout > 0.9) throw bad("dropout fraction must be in [0, 0.9]");
  if (!std::isfinite(saccade_loss_deg_s) || saccade_loss_deg_s < 0) throw bad("saccade loss velocity must be >= 0 (0: off)");
}

TrackerParams tracker_preset(std::string_view name) {
  TrackerParams p;
  if (name == "ideal") return p;
  if (name == "fove0") {
    // Measured or published: rate (FOVE 0 spec sheet: 120 Hz eye cameras), delay (Stein et
    // al. 2021: 15 ms, the fastest of the HMDs measured). Assumed (no published figure):
    // jitter, noise, dropouts. docs/gaze.md, "Tracker model".
    p.name = "fove0";
    p.rate_hz = 120;
    p.delay_ns = 15'000'000;
    p.jitter_ns = 2'000'000;
    p.noise_deg = 0.25;
    p.dropout = 0.01;
    p.burst_ns = 30'000'000;
    return p;
  }
  throw core::InputError("unknown tracker preset \"" + std::string(name) + "\" (fove0, ideal)");
}

// The tracker proper in virtual time (tracker clock from 0): sample k in order, with its
// measurement time (t_ns = device_time_ns) and delivery time (host_time_ns). Every sample
// draws the same random numbers whatever the parameters, so runs that differ in one
// parameter differ only through it.
struct TrackerModel::Generator {
  explicit Generator(const TrackerParams& params) : p(params), rng(params.seed) {
    // Two-state (Gilbert) dropout chain: bursts last `burst` samples on average (geometric),
    // and the stationary lost fraction p_enter / (p_enter + p_leave) is `dropout`.
    const double burst = std::max(1.0, static_cast<double>(p.burst_ns) * 1e-9 * p.rate_hz);
    p_leave = 1 / burst;
    p_enter = p.dropout / (burst * (1 - p.dropout));
  }

  GazeSample next(const std::function<GazeSample(core::TimeNs)>& truth_at) {
    const core::TimeNs t = std::llround(static_cast<double>(k++) * 1e9 / p.rate_hz);
    const GazeSample truth = truth_at(t);
    const double u_jitter = uniform(rng), u_drop = uniform(rng);
    double n[4];
    for (double& x : n) x = normal(rng);

    GazeSample s = truth;
    s.t_ns = s.device_time_ns = t;
    s.motion = Motion::Unknown;
    // In order, as over one USB pipe: a late sample holds back the ones after it.
    last_delivery = std::max<core::TimeNs>(last_delivery, t + p.delay_ns + std::llround(u_jitter * static_cast<double>(p.jitter_ns)));
    s.host_time_ns = last_delivery;
    in_burst = in_burst ? u_drop >= p_leave : u_drop < p_enter;

    const bool fast = p.saccade_loss_deg_s > 0 && have_prev && truth.combined.tracked() &&
                      core::angle_deg(prev_dir, truth.combined.dir) / (static_cast<double>(t - prev_t) * 1e-9) > p.saccade_loss_deg_s;
    have_prev = truth.combined.tracked();
    prev_dir = truth.combined.dir;
    prev_t = t;

    if (!truth.combined.tracked()) return s;  // blink or no truth: the tracker has no pupil either
    if (in_burst || fast) {
      for (EyeGaze* e : {&s.combined, &s.left, &s.right}) {
        e->flags = kLost;
        e->confidence = 0;
      }
      return s;
    }
    if (p.noise_deg > 0) {
      perturb(s.left, n[0], n[1]);
      perturb(s.right, n[2], n[3]);
      s.combined = combine_eyes(s.left, s.right);
    }
    return s;
  }

  // Rotates a tracked direction by the angle |w| towards w, w an isotropic Gaussian vector in
  // its tangent plane with σ = noise/√2 per axis, so the angular error has RMS `noise`.
  void perturb(EyeGaze& e, double nx, double ny) const {
    if (!e.tracked()) return;
    const glm::dvec3 d = glm::normalize(e.dir);
    const glm::dvec3 up = std::abs(d.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(d, up)), v = glm::cross(u, d);
    const double sigma = p.noise_deg * std::numbers::pi / 180 / std::numbers::sqrt2;
    const glm::dvec3 w = sigma * (nx * u + ny * v);
    const double a = glm::length(w);
    if (a > 0) e.dir = std::cos(a) * d + std::sin(a) * (w / a);
  }

  TrackerParams p;
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> uniform{0.0, 1.0};
  std::normal_distribution<double> normal{0.0, 1.0};
  double p_enter = 0, p_leave = 1;
  std::int64_t k = 0;
  core::TimeNs last_delivery = INT64_MIN, prev_t = 0;
  bool in_burst = false, have_prev = false;
  glm::dvec3 prev_dir{0, 0, -1};
};

TrackerModel::TrackerModel(std::unique_ptr<GazeSource> truth, const TrackerParams& params, const SourceOptions& opt)
    : truth_(std::move(truth)),
      params_(params),
      opt_(opt),
      predictor_(PredictParams{.mode = opt.predict}),
      opened_ns_(core::now_ns()) {
  params_.validate();
  if (!truth_) throw core::InputError("tracker model: no ground-truth gaze source");
  if (truth_->is_live())
    throw core::InputError("tracker model: the ground truth must be a recording or synthetic gaze, not the live source " +
                           truth_->describe());
  gen_ = std::make_unique<Generator>(params_);
  if (params_.host_clock) {
    epoch_ = core::now_ns();
    thread_ = std::thread(&TrackerModel::deliver_loop, this);
  }
}

TrackerModel::~TrackerModel() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

std::string TrackerModel::describe() const {
  char buf[200];
  std::snprintf(buf, sizeof buf, "tracker %s (%g Hz, delay %g ms, jitter %g ms, noise %g deg, dropout %g)%s over ",
                params_.name.c_str(), params_.rate_hz, core::ns_to_ms(params_.delay_ns), core::ns_to_ms(params_.jitter_ns),
                params_.noise_deg, params_.dropout, params_.host_clock ? " on the host clock" : "");
  return buf + truth_->describe();
}

GazeSample TrackerModel::truth_at(core::TimeNs t) {
  std::lock_guard lock(truth_mutex_);
  GazeSample s = truth_->sample_at(t - epoch_);
  if (s.t_ns != kNoSample) s.t_ns += epoch_;
  return s;
}

void TrackerModel::restart() {
  gen_ = std::make_unique<Generator>(params_);
  win_.clear();
  trimmed_ = false;
}

namespace {
// Keeps window_ns of measurement time, and always the two newest samples.
void push_bounded(std::deque<GazeSample>& win, const GazeSample& s, core::TimeNs window_ns, bool& trimmed) {
  win.push_back(s);
  while (win.size() > 2 && win.back().t_ns - win[1].t_ns > window_ns) {
    win.pop_front();
    trimmed = true;
  }
}
}  // namespace

void TrackerModel::deliver_loop() {
  // epoch_ is 0 here only in virtual time, where this loop does not run.
  const auto truth = [this](core::TimeNs t) { return truth_at(t + epoch_); };
  while (true) {
    GazeSample s = gen_->next(truth);
    s.t_ns += epoch_;
    const core::TimeNs due = epoch_ + s.host_time_ns;
    std::unique_lock lock(mutex_);
    while (!stop_ && core::now_ns() < due) wake_.wait_for(lock, std::chrono::nanoseconds(due - core::now_ns()));
    if (stop_) return;
    s.host_time_ns = core::now_ns();  // the real receive time, at or after the modelled one
    push_bounded(win_, s, opt_.window_ns, trimmed_);
  }
}

GazeSample TrackerModel::read_at(core::TimeNs read_ns, core::TimeNs target_ns) {
  const core::TimeNs t = std::min(read_ns, target_ns);
  std::lock_guard lock(mutex_);
  if (!params_.host_clock) {
    if (trimmed_ && !win_.empty() && t < win_.front().host_time_ns) restart();
    const auto truth = [this](core::TimeNs tt) { return truth_at(tt); };
    // Deliveries are in order: once one is past t, every later one is too.
    while (win_.empty() || win_.back().host_time_ns <= t) push_bounded(win_, gen_->next(truth), opt_.window_ns, trimmed_);
  }
  const auto it = std::upper_bound(win_.begin(), win_.end(), t,
                                   [](core::TimeNs x, const GazeSample& s) { return x < s.host_time_ns; });
  if (it == win_.begin()) {  // nothing delivered yet
    GazeSample s;
    s.t_ns = kNoSample;
    return s;
  }
  const std::size_t count = static_cast<std::size_t>(it - win_.begin());
  GazeSample s = win_[count - 1];
  // Stale when the tracker stopped delivering, not when it is merely slow (its delay).
  if (t - s.host_time_ns > opt_.max_gap_ns) {
    for (EyeGaze* e : {&s.combined, &s.left, &s.right}) {
      e->flags = kLost;
      e->confidence = 0;
    }
    return s;
  }
  return opt_.predicts() && target_ns > s.t_ns ? predictor_.predict(win_, count, target_ns, opt_.horizon_ns) : s;
}

GazeSample TrackerModel::latest() { return sample_at(params_.host_clock ? core::now_ns() : core::now_ns() - opened_ns_); }

bool take_tracker_options(SourceUri& u, TrackerParams& p) {
  static const char* const keys[] = {"tracker",       "tracker_rate",    "tracker_delay",        "tracker_jitter", "tracker_noise",
                                     "tracker_dropout", "tracker_burst", "tracker_saccade_loss", "tracker_seed",   "tracker_clock"};
  if (std::none_of(std::begin(keys), std::end(keys), [&](const char* k) { return u.query.count(k) > 0; })) return false;
  const std::string preset = u.take("tracker");
  p = tracker_preset(preset.empty() ? "fove0" : preset);
  const auto duration = [&](const char* key, core::TimeNs& v) {
    if (const std::string s = u.take(key); !s.empty()) v = core::parse_duration_ns(s, "gaze source \"" + u.text + "\": " + key);
  };
  p.rate_hz = u.take_number("tracker_rate", p.rate_hz, 10, 2000);
  duration("tracker_delay", p.delay_ns);
  duration("tracker_jitter", p.jitter_ns);
  duration("tracker_burst", p.burst_ns);
  p.noise_deg = u.take_number("tracker_noise", p.noise_deg, 0, 10);
  p.dropout = u.take_number("tracker_dropout", p.dropout, 0, 0.9);
  p.saccade_loss_deg_s = u.take_number("tracker_saccade_loss", p.saccade_loss_deg_s, 0, 1e5);
  p.seed = static_cast<std::uint64_t>(u.take_number("tracker_seed", static_cast<double>(p.seed), 0, 9e15));
  const std::string clock = u.take("tracker_clock");
  if (!clock.empty() && clock != "virtual" && clock != "host")
    throw core::InputError("gaze source \"" + u.text + "\": tracker_clock must be virtual or host");
  p.host_clock = clock == "host";
  p.validate();
  return true;
}

}  // namespace fovea::devices
