#include "fovea/devices/synthetic.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"

namespace fovea::devices {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

struct TaskModel {
  double fix_median_ms;    // lognormal fixation durations
  double fix_sigma_log;
  double blinks_per_min;   // Bentivoglio 1997: 17/min at rest, 4.5/min reading
};
TaskModel task_model(SynthTask t) {
  switch (t) {
    case SynthTask::Reading: return {230, 0.35, 4.5};        // Rayner 1998: 225–250 ms mean
    case SynthTask::Search: return {275, 0.40, 17.0};        // Rayner 1998: visual search ~275 ms
    case SynthTask::FixationGrid: return {1000, 0.10, 17.0}; // calibration-like dwell
    case SynthTask::Pursuit: return {0, 0, 17.0};
  }
  return {230, 0.4, 17};
}

glm::dvec3 dir_from_angles(double az_deg, double el_deg) {
  const double a = az_deg * kDeg, e = el_deg * kDeg;
  return {std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)};
}
glm::dvec2 angles_of(glm::dvec3 d) {
  return {std::atan2(d.x, -d.z) / kDeg, std::asin(std::clamp(d.y, -1.0, 1.0)) / kDeg};
}
glm::dvec3 slerp(glm::dvec3 a, glm::dvec3 b, double u) {
  const double om = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
  if (om < 1e-9) return a;
  const double s = std::sin(om);
  return glm::normalize((std::sin((1 - u) * om) * a + std::sin(u * om) * b) / s);
}

// Asymmetric velocity profile: v(τ) ∝ τ^k (1−τ)^(2k), peak at τ = 1/3 (acceleration about a
// third of the saccade). Its mean/peak ratio m(k) falls from 1 (k→0, flat) as k grows; k is
// chosen so that the profile meets both main-sequence relations: A = m·Vp·D.
double mean_over_peak(double k) {
  const double lb = std::lgamma(k + 1) + std::lgamma(2 * k + 1) - std::lgamma(3 * k + 2);
  const double lmode = k * std::log(1.0 / 3) + 2 * k * std::log(2.0 / 3);
  return std::exp(lb - lmode);
}
double shape_for_ratio(double m) {
  double lo = 1e-4, hi = 60;
  for (int i = 0; i < 80; ++i) {
    const double mid = std::sqrt(lo * hi);
    (mean_over_peak(mid) > m ? lo : hi) = mid;
  }
  return std::sqrt(lo * hi);
}

}  // namespace

namespace main_sequence {
double duration_ms(double a) { return kSlopeMsPerDeg * a + kInterceptMs; }
double peak_velocity_deg_s(double a) { return kVmaxDegS * (1 - std::exp(-a / kCDeg)); }
}  // namespace main_sequence

SynthTask parse_synth_task(std::string_view s) {
  if (s == "reading") return SynthTask::Reading;
  if (s == "search") return SynthTask::Search;
  if (s == "pursuit") return SynthTask::Pursuit;
  if (s == "fixation-grid") return SynthTask::FixationGrid;
  throw core::InputError("unknown synthetic task \"" + std::string(s) + "\" (reading, search, pursuit, fixation-grid)");
}
const char* synth_task_name(SynthTask t) {
  switch (t) {
    case SynthTask::Reading: return "reading";
    case SynthTask::Search: return "search";
    case SynthTask::Pursuit: return "pursuit";
    case SynthTask::FixationGrid: return "fixation-grid";
  }
  return "?";
}
const char* synth_event_name(SynthEvent::Kind k) {
  static constexpr const char* n[] = {"fixation", "saccade", "microsaccade", "catch-up-saccade", "blink", "dropout"};
  return n[k];
}

void SynthParams::validate() const {
  auto bad = [](const std::string& w) { throw core::InputError("synthetic gaze: " + w); };
  if (!(rate_hz >= 60 && rate_hz <= 1000)) bad("rate must be within 60..1000 Hz");
  if (!std::isfinite(seconds) || seconds > 1e6) bad("seconds must be finite and at most 1e6");
  if (!(noise_deg >= 0 && noise_deg <= 10)) bad("noise must be within 0..10 degrees RMS");
  if (!(noise_color >= 0 && noise_color < 0.99)) bad("noise colour must be within [0, 0.99)");
  if (!(dropout_per_s >= 0 && dropout_per_s <= 10)) bad("dropout rate must be within 0..10 per second");
  if (!(fixation_distance_m > 0.05 && fixation_distance_m < 1e3)) bad("fixation distance must be in (0.05, 1000) m");
  if (!(ipd_m >= 0 && ipd_m < 0.2)) bad("ipd must be within [0, 0.2) m");
}

struct SyntheticStream::State {
  enum Mode { Fix, Sacc, Pursue };
  struct Saccade {
    double t0 = 0, dur = 0;
    glm::dvec3 a, b;
    std::array<double, 129> cdf{};  // position fraction at τ = i/128
    SynthEvent::Kind kind = SynthEvent::Saccade;
    double amp = 0, vp = 0;
  };

  SynthParams p;
  TaskModel model;
  std::mt19937_64 rng;
  std::uint64_t k = 0;  // sample index
  Mode mode = Fix, after = Fix;
  glm::dvec3 eye{0, 0, -1};
  double fix_start = 0, fix_end = 0, next_micro = 0;
  Saccade sac;
  double next_blink = 0, blink_start = -1, blink_end = -1;
  double next_drop = 0, drop_start = -1, drop_end = -1;
  double noise[2][2] = {};
  int line = 0;                 // reading
  std::array<int, 9> grid{};    // fixation-grid order
  int grid_i = 0;
  double last_t = 0;

  explicit State(const SynthParams& params) : p(params), model(task_model(params.task)), rng(params.seed) {
    for (int i = 0; i < 9; ++i) grid[i] = i;
    next_blink = exp_wait(model.blinks_per_min / 60.0);
    next_drop = exp_wait(p.dropout_per_s);
    if (p.task == SynthTask::Pursuit) {
      mode = Pursue;
      eye = pursuit_target(0);
    } else {
      eye = first_target();
      start_fixation(0);
    }
  }

  double uniform() { return std::uniform_real_distribution<double>(0, 1)(rng); }
  double normal() { return std::normal_distribution<double>(0, 1)(rng); }
  double exp_wait(double rate) { return rate > 0 ? -std::log(1 - uniform()) / rate : 1e300; }
  double lognormal(double median, double sigma) { return median * std::exp(sigma * normal()); }

  glm::dvec3 first_target() {
    switch (p.task) {
      case SynthTask::Reading: return dir_from_angles(-15, 8);
      case SynthTask::FixationGrid: std::shuffle(grid.begin(), grid.end(), rng); return grid_target(grid[0]);
      default: return dir_from_angles(0, 0);
    }
  }
  static glm::dvec3 grid_target(int i) { return dir_from_angles(-15 + 15 * (i % 3), 10 - 10 * (i / 3)); }

  // Task-specific choice of the next saccade target.
  glm::dvec3 next_target() {
    const glm::dvec2 ang = angles_of(eye);
    switch (p.task) {
      case SynthTask::Reading: {  // lines ±15°, 2° apart; ~2° forward saccades, 10% regressions
        if (ang.x > 14) {  // return sweep to the next line
          line = (line + 1) % 9;
          return dir_from_angles(-15 + uniform(), 8 - 2 * line);
        }
        const double a = std::clamp(lognormal(2.0, 0.3), 0.5, 6.0);
        const double y = 8 - 2 * line;
        return dir_from_angles(uniform() < 0.1 ? ang.x - 0.75 * a : ang.x + a, y + 0.1 * normal());
      }
      case SynthTask::Search:  // anywhere in a ±20° × ±15° field
        return dir_from_angles(-20 + 40 * uniform(), -15 + 30 * uniform());
      case SynthTask::FixationGrid:
        if (++grid_i == 9) {
          grid_i = 0;
          std::shuffle(grid.begin(), grid.end(), rng);
        }
        return grid_target(grid[grid_i]);
      case SynthTask::Pursuit: break;
    }
    return eye;
  }

  // Lissajous target, peak horizontal speed 18·2π·0.35 ≈ 40 °/s: above the 30 °/s pursuit
  // limit near the centre crossings.
  static glm::dvec3 pursuit_target(double t) {
    return dir_from_angles(18 * std::sin(2 * std::numbers::pi * 0.35 * t), 8 * std::sin(2 * std::numbers::pi * 0.13 * t));
  }

  void start_fixation(double t) {
    fix_start = t;
    fix_end = t + std::clamp(lognormal(model.fix_median_ms, model.fix_sigma_log), 80.0, 3000.0) * 1e-3;
    next_micro = t + exp_wait(1.5);  // 1–2 microsaccades per second
    mode = Fix;
  }

  void start_saccade(double t, glm::dvec3 target, SynthEvent::Kind kind) {
    Saccade& s = sac;
    s.t0 = t;
    s.a = eye;
    s.b = target;
    s.kind = kind;
    s.amp = core::angle_deg(s.a, s.b);
    s.dur = main_sequence::duration_ms(s.amp) * 1e-3;
    s.vp = main_sequence::peak_velocity_deg_s(s.amp);
    // Feasible profiles need mean/peak ≤ 0.95; with Vmax = 700 and C = 14 the two fits
    // already satisfy this (m → 0.95 as A → 0), the clamp only guards the edge.
    const double m = std::clamp(s.amp / (s.vp * s.dur), 0.3, 0.95);
    s.vp = s.amp / (m * s.dur);
    const double k = shape_for_ratio(m);
    // Cumulative position fraction by trapezoid integration of the profile.
    double acc = 0, prev = 0;
    s.cdf[0] = 0;
    for (int i = 1; i <= 128; ++i) {
      const double tau = i / 128.0;
      const double v = std::pow(tau, k) * std::pow(1 - tau, 2 * k);
      acc += 0.5 * (v + prev) / 128.0;
      prev = v;
      s.cdf[i] = acc;
    }
    for (double& c : s.cdf) c /= acc;
    if (mode == Fix && kind != SynthEvent::Microsaccade) emit({SynthEvent::Fixation, ns(fix_start), ns(t)});
    after = kind == SynthEvent::Microsaccade ? Fix : (p.task == SynthTask::Pursuit ? Pursue : Fix);
    mode = Sacc;
  }

  static core::TimeNs ns(double t) { return std::llround(t * 1e9); }
  std::function<void(const SynthEvent&)>* log = nullptr;
  void emit(const SynthEvent& e) {
    if (log && *log) (*log)(e);
  }

  void advance_eye(double t, double dt) {
    if (mode == Sacc && t >= sac.t0 + sac.dur) {
      eye = sac.b;
      emit({sac.kind, ns(sac.t0), ns(sac.t0 + sac.dur), sac.amp, sac.vp});
      if (after == Fix && sac.kind != SynthEvent::Microsaccade) start_fixation(sac.t0 + sac.dur);
      mode = after;
    }
    if (mode == Fix) {
      if (t >= fix_end) {
        start_saccade(t, next_target(), SynthEvent::Saccade);
      } else if (t >= next_micro) {
        next_micro = t + exp_wait(1.5);
        const double amp = 0.1 * std::pow(10.0, uniform());  // log-uniform 0.1–1°
        if (fix_end - t > (main_sequence::duration_ms(amp) + 50) * 1e-3) {
          const double ang = 2 * std::numbers::pi * uniform();
          const glm::dvec3 e1 = glm::normalize(glm::cross(eye, glm::dvec3(0, 1, 0))), e2 = glm::cross(e1, eye);
          const glm::dvec3 off = std::cos(ang) * e1 + std::sin(ang) * e2;
          start_saccade(t, glm::normalize(eye * std::cos(amp * kDeg) + off * std::sin(amp * kDeg)), SynthEvent::Microsaccade);
        }
      }
    } else if (mode == Pursue) {
      // Eye velocity follows the target's with a speed-dependent gain (0.98 at 10 °/s, 0.75
      // at 60 °/s, linear in between), capped at 30 °/s; the position error grows and a
      // catch-up saccade lands where the target will be at its end.
      const glm::dvec3 tgt = pursuit_target(t), prev = pursuit_target(t - dt);
      const double tv = core::angle_deg(prev, tgt) / dt;
      const double gain = std::clamp(0.98 - (tv - 10) * (0.23 / 50), 0.75, 0.98);
      const double step = std::min(gain * tv, 30.0) * dt;
      const glm::dvec3 want = glm::normalize(eye + (tgt - prev));
      const double wstep = core::angle_deg(eye, want);
      eye = wstep > 1e-12 ? slerp(eye, want, std::min(1.0, step / wstep)) : eye;
      if (core::angle_deg(eye, tgt) > 2.0) {
        const double amp = core::angle_deg(eye, tgt);
        start_saccade(t, pursuit_target(t + main_sequence::duration_ms(amp) * 1e-3), SynthEvent::CatchUpSaccade);
      }
    }
    if (mode == Sacc) {
      const double u = std::clamp((t - sac.t0) / sac.dur, 0.0, 1.0) * 128;
      const int i = std::min(static_cast<int>(u), 127);
      eye = slerp(sac.a, sac.b, sac.cdf[i] + (u - i) * (sac.cdf[i + 1] - sac.cdf[i]));
    }
  }

  // Blinks and dropouts: Poisson onsets, lognormal durations.
  std::uint32_t validity(double t) {
    if (blink_end < 0 && t >= next_blink) {
      blink_start = t;
      blink_end = t + std::clamp(lognormal(200, 0.3), 100.0, 400.0) * 1e-3;
    }
    if (blink_end >= 0 && t >= blink_end) {
      emit({SynthEvent::Blink, ns(blink_start), ns(blink_end)});
      next_blink = blink_end + exp_wait(model.blinks_per_min / 60.0);
      blink_end = -1;
    }
    if (drop_end < 0 && t >= next_drop) {
      drop_start = t;
      drop_end = t + std::clamp(lognormal(40, 0.5), 5.0, 300.0) * 1e-3;
    }
    if (drop_end >= 0 && t >= drop_end) {
      emit({SynthEvent::Dropout, ns(drop_start), ns(drop_end)});
      next_drop = drop_end + exp_wait(p.dropout_per_s);
      drop_end = -1;
    }
    if (blink_end >= 0) return kBlink;
    if (drop_end >= 0) return kLost;
    return kTracked;
  }

  GazeSample step() {
    const core::TimeNs tn = std::llround(static_cast<double>(k) * 1e9 / p.rate_hz);
    const double t = static_cast<double>(tn) * 1e-9, dt = 1.0 / p.rate_hz;
    ++k;
    advance_eye(t, dt);
    const std::uint32_t flags = validity(t);
    GazeSample s;
    s.t_ns = s.device_time_ns = s.host_time_ns = tn;
    // Vergence: each eye looks at the point fixation_distance_m along the cyclopean gaze.
    const glm::dvec3 target = eye * p.fixation_distance_m;
    const double rho = p.noise_color, innov = std::sqrt(1 - rho * rho);
    for (int e = 0; e < 2; ++e) {
      const glm::dvec3 origin((e == 0 ? -0.5 : 0.5) * p.ipd_m, 0, 0);
      glm::dvec2 a = angles_of(glm::normalize(target - origin));
      for (int c = 0; c < 2; ++c) {  // AR(1) noise with stationary RMS = noise_deg
        noise[e][c] = rho * noise[e][c] + innov * p.noise_deg * normal();
        a[c] += noise[e][c];
      }
      EyeGaze& g = e == 0 ? s.left : s.right;
      g.dir = dir_from_angles(a.x, a.y);
      g.flags = flags;
      g.confidence = flags == kTracked ? 0.9 + 0.1 * uniform() : 0.0;
    }
    s.combined = combine_eyes(s.left, s.right);
    if (flags != kTracked) {
      s.combined.dir = glm::normalize(s.left.dir + s.right.dir);
      s.combined.flags = flags;
      s.combined.confidence = 0;
    }
    last_t = t;
    return s;
  }
};

SyntheticStream::SyntheticStream(const SynthParams& p) : params_(p) {
  p.validate();
  rewind();
}
SyntheticStream::~SyntheticStream() = default;

void SyntheticStream::rewind() {
  s_ = std::make_unique<State>(params_);
  s_->log = &log_;
}

void SyntheticStream::on_event(std::function<void(const SynthEvent&)> fn) { log_ = std::move(fn); }

bool SyntheticStream::next(GazeSample& out) {
  if (params_.seconds > 0 && static_cast<double>(s_->k) >= params_.seconds * params_.rate_hz) return false;
  out = s_->step();
  return true;
}

std::string SyntheticStream::describe() const {
  return "synthetic:" + std::to_string(params_.seed) + "?task=" + synth_task_name(params_.task) +
         "&rate=" + std::to_string(static_cast<int>(params_.rate_hz));
}

}  // namespace fovea::devices
