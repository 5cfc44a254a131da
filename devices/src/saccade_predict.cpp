#include "fovea/devices/saccade_predict.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>

#include "fovea/devices/synthetic.hpp"

namespace fovea::devices {
namespace {

constexpr double kRad = std::numbers::pi / 180;

bool valid(const GazeSample& s) {
  const glm::dvec3& d = s.combined.dir;
  return s.tracked() && std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z) && glm::length(d) > 0.5;
}

double speed_deg_s(glm::dvec3 a, core::TimeNs ta, glm::dvec3 b, core::TimeNs tb) {
  return core::angle_deg(a, b) / (static_cast<double>(tb - ta) * 1e-9);
}

// Displacement profile: the fraction of the amplitude covered at τ = (t − onset)/duration.
// A blend (weight w) of the minimum-jerk profile 10u³ − 15u⁴ + 6u⁵ (Flash & Hogan 1985;
// peak/mean velocity 1.875) and the flatter smoothstep 3u² − 2u³ (1.5), both half-way at
// u = 1/2, on the warped time u = τ^γ that moves that point to `half_way_fraction` of the
// duration (saccades accelerate faster than they brake, Van Opstal & Van Gisbergen 1987).
double profile(double tau, double w, double gamma) {
  const double u = std::pow(std::clamp(tau, 0.0, 1.0), gamma);
  const double min_jerk = u * u * u * (10 + u * (-15 + 6 * u));
  return w * min_jerk + (1 - w) * u * u * (3 - 2 * u);
}

// The main sequence fixes a saccade's duration D = 2.2·A + 21 ms (Carpenter 1988) and peak
// velocity Vp = Vmax(1 − e^(−A/C)) (Baloh et al. 1975), hence its peak/mean velocity
// Vp·D/A; Shape picks the blend weight with that ratio, so the fitted profile accelerates
// as a saccade of its amplitude does: the early samples are that acceleration.
class Shape {
 public:
  explicit Shape(double half_way) : gamma_(std::log(0.5) / std::log(std::clamp(half_way, 0.05, 0.95))) {
    constexpr int kSteps = 400;
    for (std::size_t i = 0; i < pom_.size(); ++i) {
      const double w = double(i) / double(pom_.size() - 1);
      double peak = 0;
      for (int k = 0; k < kSteps; ++k)
        peak = std::max(peak, (profile((k + 1.0) / kSteps, w, gamma_) - profile(double(k) / kSteps, w, gamma_)) * kSteps);
      pom_[i] = peak;
    }
  }
  double gamma() const { return gamma_; }
  double blend_for(double amp_deg) const {
    const double want = main_sequence::peak_velocity_deg_s(amp_deg) * main_sequence::duration_ms(amp_deg) * 1e-3 / amp_deg;
    if (want <= pom_.front()) return 0;
    for (std::size_t i = 1; i < pom_.size(); ++i)
      if (want <= pom_[i]) return (double(i - 1) + (want - pom_[i - 1]) / (pom_[i] - pom_[i - 1])) / double(pom_.size() - 1);
    return 1;
  }

 private:
  double gamma_;
  std::array<double, 11> pom_{};  // peak/mean velocity at w = 0, 0.1, …, 1
};

core::TimeNs duration_for(double amp_deg) { return std::llround(main_sequence::duration_ms(amp_deg) * 1e6); }

struct Point {
  core::TimeNs t;
  double s;  // displacement along the saccade, degrees
};

// Sum of squared residuals of the samples against a saccade of amplitude `amp` from t0.
double misfit(const std::vector<Point>& pts, core::TimeNs t0, double amp, const Shape& shape) {
  const double dur = static_cast<double>(duration_for(amp));
  const double w = shape.blend_for(amp);
  double sse = 0;
  for (const Point& p : pts) {
    const double r = p.s - amp * profile(static_cast<double>(p.t - t0) / dur, w, shape.gamma());
    sse += r * r;
  }
  return sse;
}

}  // namespace

glm::dvec3 LandingEstimate::at(core::TimeNs t) const {
  // In double: t may be any time, and t − onset_ns must not overflow.
  const double tau = duration_ns > 0 ? (static_cast<double>(t) - static_cast<double>(onset_ns)) / static_cast<double>(duration_ns) : 1.0;
  const double s = amplitude_deg * profile(tau, blend, skew) * kRad;
  return glm::normalize(std::cos(s) * onset_dir + std::sin(s) * toward);
}

LandingEstimate estimate_landing(const std::deque<GazeSample>& h, std::size_t count, const LandingParams& p) {
  LandingEstimate e;
  count = std::min(count, h.size());
  if (count == 0 || !valid(h[count - 1])) return e;
  // Back from the newest sample over the intervals faster than the onset speed; the sample
  // that ends the first slow interval is where the saccade left the fixation.
  struct Sample {
    core::TimeNs t;
    glm::dvec3 d;
  };
  std::vector<Sample> run;  // newest first
  Sample b{h[count - 1].t_ns, glm::normalize(h[count - 1].combined.dir)};
  std::size_t i = count - 1;
  bool anchored = false;
  while (i-- > 0) {
    if (!valid(h[i])) continue;
    const Sample a{h[i].t_ns, glm::normalize(h[i].combined.dir)};
    if (b.t <= a.t || b.t - a.t > p.max_gap_ns) return e;  // no onset within reach
    if (speed_deg_s(a.d, a.t, b.d, b.t) < p.onset_deg_s) {
      anchored = true;
      break;
    }
    run.push_back(b);
    b = a;
  }
  if (!anchored || run.empty()) return e;
  const Sample anchor = b;
  // The onset direction: the fixation's last samples averaged against tracker noise; their
  // spread is the noise the fit is judged against.
  std::vector<glm::dvec3> fix{anchor.d};
  for (std::size_t k = i + 1; k-- > 0;)
    if (valid(h[k])) {
      if (anchor.t - h[k].t_ns > p.fixation_ns) break;
      fix.push_back(glm::normalize(h[k].combined.dir));
    }
  glm::dvec3 sum(0);
  for (const glm::dvec3& d : fix) sum += d;
  e.in_saccade = true;
  e.onset_dir = e.landing_dir = glm::normalize(sum);
  double spread = 0;
  for (const glm::dvec3& d : fix) spread += std::pow(core::angle_deg(d, e.onset_dir), 2);
  // Per axis, from the 2-D spread (n − 1 degrees of freedom).
  const double noise_deg = fix.size() > 1 ? std::sqrt(spread / (2.0 * static_cast<double>(fix.size() - 1))) : 0.0;
  e.onset_ns = anchor.t;
  const glm::dvec3 newest = run.front().d;
  e.progress_deg = core::angle_deg(e.onset_dir, newest);
  const glm::dvec3 side = newest - glm::dot(newest, e.onset_dir) * e.onset_dir;
  if (!(glm::length(side) > 1e-9)) return e;  // no direction to predict along
  e.toward = glm::normalize(side);

  std::vector<Point> pts;
  pts.push_back({anchor.t, 0.0});
  for (const Sample& s : run)
    pts.push_back({s.t, std::atan2(glm::dot(s.d, e.toward), glm::dot(s.d, e.onset_dir)) / kRad});
  std::sort(pts.begin(), pts.end(), [](const Point& x, const Point& y) { return x.t < y.t; });
  // The speeds so far bound the amplitude through the main sequence: a saccade reaching a
  // peak of V has A ≥ A(V); once its speed has fallen well below that peak, the peak is
  // passed and A ≈ A(V) (Vp = Vmax(1 − e^(−A/C)) inverted); before, its peak is taken to be
  // at most 1.5·V. Without the upper bound a long saccade still accelerating fits the
  // first samples of a shorter one about as well.
  double peak = 0, now = 0;
  std::size_t now_from = 0;  // the speed `now` is from this point to the newest
  for (std::size_t k = 1, j = 0; k < pts.size(); ++k) {
    while (j + 1 < k && pts[k].t - pts[j + 1].t >= p.speed_span_ns) ++j;
    now = (pts[k].s - pts[j].s) / (static_cast<double>(pts[k].t - pts[j].t) * 1e-9);
    now_from = j;
    peak = std::max(peak, now);
  }
  const auto amp_of_speed = [](double v) {
    return -main_sequence::kCDeg * std::log(1 - std::min(v, 0.99 * main_sequence::kVmaxDegS) / main_sequence::kVmaxDegS);
  };
  // Noise can make intervals before the onset fast too: the saccade starts after the last
  // sample still within the fixation's noise (3σ), and, as that sample may already be
  // moving slowly, possibly somewhat before it.
  std::size_t start = 0;
  for (std::size_t k = 1; k + 1 < pts.size(); ++k)
    if (pts[k].s <= 3 * noise_deg) start = k;
  const core::TimeNs t_still = pts[start].t, t_first = pts[start + 1].t;
  const Shape shape(p.half_way_fraction);
  // Speeds carry the noise of two samples over one span.
  const double speed_noise = 2 * std::sqrt(2.0) * noise_deg / (static_cast<double>(p.speed_span_ns) * 1e-9);
  const double lo = std::clamp(std::max(e.progress_deg, amp_of_speed(0.8 * (peak - speed_noise))), 0.1, p.max_amplitude_deg);
  const double hi = std::clamp(amp_of_speed(now < 0.8 * peak ? 1.25 * peak : 1.5 * peak + speed_noise), lo, p.max_amplitude_deg);
  // Least squares over the onset time (from somewhat before the last still sample to the
  // first one in flight) and the amplitude within those bounds: a grid, then golden section.
  constexpr int kOnsets = 16, kAmps = 64;
  double best = INFINITY, best_amp = lo;
  core::TimeNs best_t0 = anchor.t;
  int best_k = 0;
  const core::TimeNs t0_min = t_still - std::max<core::TimeNs>(5'000'000, t_first - t_still);
  std::array<double, kAmps> by_amp;  // the best misfit of each amplitude over the onsets
  by_amp.fill(INFINITY);
  for (int j = 0; j <= kOnsets; ++j) {
    const core::TimeNs t0 = t0_min + (t_first - t0_min) * j / kOnsets;
    for (int k = 0; k < kAmps; ++k) {
      const double amp = lo * std::pow(hi / lo, k / double(kAmps - 1));
      const double f = misfit(pts, t0, amp, shape);
      by_amp[std::size_t(k)] = std::min(by_amp[std::size_t(k)], f);
      if (f < best) {
        best = f;
        best_amp = amp;
        best_t0 = t0;
        best_k = k;
      }
    }
  }
  const auto amp_at = [&](int k) { return lo * std::pow(hi / lo, std::clamp(k, 0, kAmps - 1) / double(kAmps - 1)); };
  double a = amp_at(best_k - 1), c = amp_at(best_k + 1);
  const double g = (std::sqrt(5.0) - 1) / 2;
  for (int it = 0; it < 40 && c - a > 1e-4; ++it) {
    const double x1 = c - g * (c - a), x2 = a + g * (c - a);
    if (misfit(pts, best_t0, x1, shape) < misfit(pts, best_t0, x2, shape)) c = x2;
    else a = x1;
  }
  if (const double amp = (a + c) / 2, f = misfit(pts, best_t0, amp, shape); f < best) {
    best = f;
    best_amp = amp;
  }
  e.amplitude_deg = best_amp;
  e.onset_ns = best_t0;
  e.duration_ns = duration_for(best_amp);
  e.blend = shape.blend_for(best_amp);
  e.skew = shape.gamma();
  e.landing_dir = e.at(e.onset_ns + e.duration_ns);
  const double rms = std::sqrt(best / static_cast<double>(pts.size()));
  // Early in a saccade (before its peak velocity, with few noisy samples) a short and a long
  // saccade can explain the samples equally well: an amplitude half or twice the best one
  // that fits within the fixation's noise makes the estimate ambiguous (the newest sample
  // is then used).
  const double tolerance = best + static_cast<double>(pts.size()) * noise_deg * noise_deg;
  bool ambiguous = false;
  for (int k = 0; k < kAmps; ++k)
    if (std::abs(std::log(amp_at(k) / best_amp)) > std::log(2.0) && by_amp[std::size_t(k)] <= tolerance) ambiguous = true;
  // The fitted saccade must move as fast as the eye does now (the speed over the last span).
  const auto model_at = [&](core::TimeNs t) {
    return best_amp * profile(static_cast<double>(t - e.onset_ns) / static_cast<double>(e.duration_ns), e.blend, e.skew);
  };
  const core::TimeNs t_new = pts.back().t, t_old = pts[now_from].t;
  const double v_model = (model_at(t_new) - model_at(t_old)) / (static_cast<double>(t_new - t_old) * 1e-9);
  const bool moves_alike = std::abs(v_model - now) <= 0.3 * std::max(now, v_model) + speed_noise;
  e.confident = moves_alike && !ambiguous && run.size() >= p.min_samples && e.progress_deg >= p.min_progress_deg &&
                rms <= std::max(0.5, p.max_rms_fraction * best_amp);
  return e;
}

bool SaccadeOnsetDetector::add(const GazeSample& s) {
  if (!valid(s)) return false;
  const glm::dvec3 d = glm::normalize(s.combined.dir);
  if (!have_ || s.t_ns <= last_t_ || s.t_ns - last_t_ > p_.max_gap_ns) {
    have_ = true;
    fired_ = false;
    last_t_ = s.t_ns;
    last_ = anchor_ = d;
    return false;
  }
  const double v = speed_deg_s(last_, last_t_, d, s.t_ns);
  last_ = d;
  last_t_ = s.t_ns;
  if (v < p_.onset_deg_s) {
    anchor_ = d;
    fired_ = false;
    return false;
  }
  if (fired_ || core::angle_deg(anchor_, d) < p_.min_progress_deg) return false;
  fired_ = true;
  return true;
}

}  // namespace fovea::devices
