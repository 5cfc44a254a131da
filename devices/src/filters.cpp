#include "fovea/devices/filters.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"
#include "fovea/devices/synthetic.hpp"

namespace fovea::devices {

namespace {
constexpr double kDeg = 180.0 / std::numbers::pi;

// Gaze angles (degrees) on the tangent plane: az = atan(x/−z), el = atan(y/−z), and back.
bool to_angles(const glm::dvec3& d, glm::dvec2& a) {
  if (!(d.z < -1e-9) || !std::isfinite(d.x + d.y + d.z)) return false;
  a = {std::atan(d.x / -d.z) * kDeg, std::atan(d.y / -d.z) * kDeg};
  return true;
}
glm::dvec3 from_angles(glm::dvec2 a) {
  a = glm::clamp(a, glm::dvec2(-89.0), glm::dvec2(89.0));
  return glm::normalize(glm::dvec3(std::tan(a.x / kDeg), std::tan(a.y / kDeg), -1.0));
}
EyeGaze& slot(GazeSample& s, int i) { return i == 0 ? s.combined : i == 1 ? s.left : s.right; }
// Moves every tracked eye by the same change of gaze angles (the eyes keep their vergence).
GazeSample shifted(GazeSample s, glm::dvec2 delta) {
  for (int k = 0; k < 3; ++k) {
    EyeGaze& g = slot(s, k);
    glm::dvec2 a;
    if (g.tracked() && to_angles(g.dir, a)) g.dir = from_angles(a + delta);
  }
  return s;
}

// ---- ivt: gap fill + classification ---------------------------------------------------
class IvtStream final : public SampleStream {
 public:
  IvtStream(std::unique_ptr<SampleStream> in, const IvtParams& p) : in_(std::move(in)), p_(p), cls_(p) {}
  bool next(GazeSample& out) override {
    while (out_.empty()) {
      GazeSample s;
      if (!in_->next(s)) {
        if (!in_->live()) flush_gap(nullptr);
        if (out_.empty()) return false;
        break;
      }
      if (s.combined.flags == kLost && have_last_) {
        gap_.push_back(s);
        if (s.t_ns - last_.t_ns >= p_.gap_fill_ns) flush_gap(nullptr);
        continue;
      }
      flush_gap(s.tracked() ? &s : nullptr);
      emit(s);
    }
    out = out_.front();
    out_.pop_front();
    return true;
  }
  bool rewindable() const override { return in_->rewindable(); }
  void rewind() override {
    in_->rewind();
    cls_.reset();
    gap_.clear();
    out_.clear();
    have_last_ = false;
  }
  bool live() const override { return in_->live(); }
  std::string describe() const override { return in_->describe() + " | ivt"; }

 private:
  // Ends a gap: filled by interpolation if it closes with a tracked sample in time.
  void flush_gap(const GazeSample* end) {
    const bool fill = end && have_last_ && end->t_ns - last_.t_ns < p_.gap_fill_ns;
    for (GazeSample g : gap_) {
      if (fill) {
        GazeSample i = interpolate(last_, *end, g.t_ns);
        for (int k = 0; k < 3; ++k) {
          slot(g, k) = slot(i, k);
          slot(g, k).confidence *= 0.5;  // filled, not measured
        }
      }
      emit(g);
    }
    gap_.clear();
  }
  void emit(GazeSample& s) {
    s.motion = cls_.classify(s);
    if (s.tracked()) {
      last_ = s;
      have_last_ = true;
    }
    out_.push_back(s);
  }
  std::unique_ptr<SampleStream> in_;
  IvtParams p_;
  IvtClassifier cls_;
  std::deque<GazeSample> gap_, out_;
  GazeSample last_;
  bool have_last_ = false;
};

// ---- oneeuro ---------------------------------------------------------------------------
class OneEuroStream final : public SampleStream {
 public:
  OneEuroStream(std::unique_ptr<SampleStream> in, const OneEuroParams& p) : in_(std::move(in)), p_(p) { reset(); }
  bool next(GazeSample& s) override {
    if (!in_->next(s)) return false;
    for (int k = 0; k < 3; ++k) {
      EyeGaze& g = slot(s, k);
      State& st = state_[k];
      glm::dvec2 a;
      if (!g.tracked() || !to_angles(g.dir, a)) {
        continue;  // untracked: untouched; the filter restarts after a dropout
      }
      const bool fresh = !st.have || s.t_ns - st.t > p_.reset_gap_ns;
      if (fresh) {
        st.f[0].reset();
        st.f[1].reset();
      }
      const double dt = fresh ? 0 : static_cast<double>(s.t_ns - st.t) * 1e-9;
      a = {st.f[0].filter(a.x, dt), st.f[1].filter(a.y, dt)};
      g.dir = from_angles(a);
      st.have = true;
      st.t = s.t_ns;
    }
    return true;
  }
  bool rewindable() const override { return in_->rewindable(); }
  void rewind() override {
    in_->rewind();
    reset();
  }
  bool live() const override { return in_->live(); }
  std::string describe() const override { return in_->describe() + " | oneeuro"; }

 private:
  struct State {
    OneEuro f[2];
    bool have = false;
    core::TimeNs t = 0;
  };
  void reset() {
    for (State& s : state_) s = State{{OneEuro(p_), OneEuro(p_)}, false, 0};
  }
  std::unique_ptr<SampleStream> in_;
  OneEuroParams p_;
  State state_[3];
};

}  // namespace

double OneEuro::filter(double x, double dt) {
  auto alpha = [&](double cutoff) {
    const double tau = 1.0 / (2 * std::numbers::pi * cutoff);
    return 1.0 / (1.0 + tau / dt);
  };
  if (!init_ || !(dt > 0)) {
    if (!init_) dx_ = 0;
    init_ = true;
    x_ = x;
    return x;
  }
  const double dx = (x - x_) / dt;
  dx_ += alpha(p_.d_cutoff_hz) * (dx - dx_);
  const double cutoff = p_.min_cutoff_hz + p_.beta * std::abs(dx_);
  x_ += alpha(cutoff) * (x - x_);
  return x_;
}

std::unique_ptr<SampleStream> apply_filters(std::unique_ptr<SampleStream> s, std::string_view spec, const FilterParams& p) {
  std::size_t start = 0;
  while (start < spec.size()) {
    const std::size_t comma = spec.find(',', start);
    const std::string_view name = spec.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    if (name == "ivt") s = std::make_unique<IvtStream>(std::move(s), p.ivt);
    else if (name == "oneeuro") s = std::make_unique<OneEuroStream>(std::move(s), p.one_euro);
    else if (!name.empty())
      throw core::InputError("unknown gaze filter \"" + std::string(name) +
                             "\" (ivt, oneeuro; losses and blinks are handled by the foveation gaze)");
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return s;
}

GazeSample GazePredictor::predict(const std::deque<GazeSample>& h, std::size_t count, core::TimeNs t,
                                  core::TimeNs horizon) const {
  const GazeSample& last = h[count - 1];
  GazeSample out = last;
  if (!last.tracked() || t <= last.t_ns) return out;
  const double ahead = static_cast<double>(std::min(t - last.t_ns, horizon)) * 1e-9;
  glm::dvec2 a_last;
  if (p_.mode == PredictMode::None || !to_angles(last.combined.dir, a_last)) return out;
  if (p_.mode == PredictMode::Landing) {
    // A fitted saccade in flight: its trajectory at t, i.e. its landing point once it is
    // over. Not capped by the horizon: the fit bounds it (Arabadzhiyska et al. 2017 render
    // for the landing point for the rest of the saccade).
    const LandingEstimate e = estimate_landing(h, count, p_.landing);
    glm::dvec2 a_pred;
    if (e.confident && to_angles(e.at(t), a_pred)) return shifted(out, a_pred - a_last);
  }
  // Sample-to-sample speeds backwards from the newest: the current motion and, in a
  // saccade, its onset and peak.
  std::size_t i = count - 1;
  double peak = 0, current = -1;
  glm::dvec2 onset_angles = a_last, window_start = a_last;
  core::TimeNs window_t = last.t_ns;
  bool in_saccade = true;
  while (i > 0) {
    const GazeSample& a = h[i - 1];
    const GazeSample& b = h[i];
    if (!a.tracked() || !b.tracked() || b.t_ns <= a.t_ns) break;
    glm::dvec2 pa, pb;
    if (!to_angles(a.combined.dir, pa) || !to_angles(b.combined.dir, pb)) break;
    const double v = glm::length(pb - pa) / (static_cast<double>(b.t_ns - a.t_ns) * 1e-9);
    if (current < 0) {
      current = v;
      in_saccade = v >= p_.saccade_deg_s;
    }
    if (in_saccade) {
      if (v < p_.saccade_deg_s) break;  // reached the onset
      peak = std::max(peak, v);
      onset_angles = pa;
    } else {
      // The pursuit window ends where a saccade does: a jump measured into it (a step between
      // two samples of a slow recording) would be extrapolated as motion, 6° past a 32° step.
      if (last.t_ns - a.t_ns > p_.velocity_window_ns || v >= p_.saccade_deg_s) break;
      window_start = pa;
      window_t = a.t_ns;
    }
    --i;
  }
  glm::dvec2 pred = a_last;
  if (current < 0) return out;  // a single tracked sample: hold
  if (in_saccade) {
    // No extrapolation across a saccade: hold, or once the peak has passed, land where the
    // main sequence says a saccade with this peak velocity ends (Vp = Vmax(1 − e^(−A/C))).
    const glm::dvec2 path = a_last - onset_angles;
    const double done = glm::length(path);
    if (current < 0.9 * peak && done > 1e-9) {
      const double vp = std::min(peak, 0.99 * main_sequence::kVmaxDegS);
      const double amp = -main_sequence::kCDeg * std::log(1 - vp / main_sequence::kVmaxDegS);
      if (amp > done) pred = onset_angles + path / done * amp;
    }
  } else if (window_t < last.t_ns) {
    const glm::dvec2 v = (a_last - window_start) / (static_cast<double>(last.t_ns - window_t) * 1e-9);
    pred = a_last + v * ahead;  // constant velocity (fixation drift, pursuit)
  }
  return shifted(out, pred - a_last);
}

}  // namespace fovea::devices
