#include "fovea/devices/gaze.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "fovea/core/error.hpp"
#include "fovea/devices/filters.hpp"
#include "fovea/devices/readers.hpp"
#include "fovea/devices/screen.hpp"
#include "fovea/devices/synthetic.hpp"
#include "fovea/devices/timeline.hpp"
#include "fovea/devices/tracker_model.hpp"
#include "source_uri.hpp"

namespace fovea::devices {

void SampleStream::rewind() { throw std::logic_error(describe() + ": not rewindable"); }

GazeSample GazeSource::truth_at(core::TimeNs) {
  GazeSample s;
  s.t_ns = kNoSample;
  return s;
}

PredictMode parse_predict_mode(std::string_view s) {
  if (s == "none") return PredictMode::None;
  if (s == "linear") return PredictMode::Linear;
  if (s == "landing") return PredictMode::Landing;
  throw core::InputError("unknown prediction mode \"" + std::string(s) + "\" (none, linear, landing)");
}

const char* predict_mode_name(PredictMode m) {
  switch (m) {
    case PredictMode::None: return "none";
    case PredictMode::Linear: return "linear";
    case PredictMode::Landing: return "landing";
  }
  return "?";
}

EyeGaze combine_eyes(const EyeGaze& l, const EyeGaze& r) {
  EyeGaze c;
  if (l.tracked() && r.tracked()) {
    c.dir = glm::normalize(l.dir + r.dir);
    c.confidence = std::min(l.confidence, r.confidence);
    c.flags = kTracked;
  } else if (l.tracked() || r.tracked()) {
    c = l.tracked() ? l : r;
  } else {
    c.dir = l.dir;
    c.flags = ((l.flags | r.flags) & kBlink) ? kBlink : kLost;
  }
  return c;
}

namespace {
EyeGaze lerp_eye(const EyeGaze& a, const EyeGaze& b, double u) {
  if (a.tracked() && b.tracked()) {
    EyeGaze g;
    const glm::dvec3 d = a.dir + u * (b.dir - a.dir);
    const double n = glm::length(d);
    g.dir = n > 1e-12 ? d / n : (u < 0.5 ? a.dir : b.dir);
    g.confidence = a.confidence + u * (b.confidence - a.confidence);
    g.flags = kTracked;
    return g;
  }
  return u < 0.5 ? a : b;
}
}  // namespace

GazeSample interpolate(const GazeSample& a, const GazeSample& b, core::TimeNs t) {
  const double span = static_cast<double>(b.t_ns - a.t_ns);
  const double u = span > 0 ? std::clamp(static_cast<double>(t - a.t_ns) / span, 0.0, 1.0) : 0.0;
  GazeSample s;
  s.t_ns = t;
  s.device_time_ns = a.device_time_ns + std::llround(u * static_cast<double>(b.device_time_ns - a.device_time_ns));
  s.host_time_ns = a.host_time_ns + std::llround(u * static_cast<double>(b.host_time_ns - a.host_time_ns));
  s.combined = lerp_eye(a.combined, b.combined, u);
  s.left = lerp_eye(a.left, b.left, u);
  s.right = lerp_eye(a.right, b.right, u);
  return s;
}

// ---- URI parsing ---------------------------------------------------------------------
SourceUri parse_source_uri(std::string_view uri) {
  SourceUri u;
  const std::string s(uri);
  const auto colon = s.find(':');
  static const char* schemes[] = {"replay", "synthetic", "hid", "usb", "hid-capture", "hid-emulated", "mouse", "openxr"};
  std::string rest = s;
  u.scheme = "replay";
  if (colon != std::string::npos) {
    const std::string sch = s.substr(0, colon);
    if (std::find_if(std::begin(schemes), std::end(schemes), [&](const char* x) { return sch == x; }) != std::end(schemes)) {
      u.scheme = sch;
      rest = s.substr(colon + 1);
    }
  } else if (s == "mouse" || s == "openxr" || s == "hid" || s == "usb") {
    u.scheme = s;
    rest.clear();
  }
  const auto q = rest.find('?');
  u.body = rest.substr(0, q);
  if (q != std::string::npos) {
    std::string query = rest.substr(q + 1);
    std::size_t start = 0;
    while (start <= query.size()) {
      const auto amp = query.find('&', start);
      const std::string kv = query.substr(start, amp == std::string::npos ? std::string::npos : amp - start);
      if (!kv.empty()) {
        const auto eq = kv.find('=');
        if (eq == std::string::npos || eq == 0)
          throw core::InputError("gaze source \"" + s + "\": query item \"" + kv + "\" is not key=value");
        u.query[kv.substr(0, eq)] = kv.substr(eq + 1);
      }
      if (amp == std::string::npos) break;
      start = amp + 1;
    }
  }
  u.text = s;
  return u;
}

std::string SourceUri::take(const std::string& key) {
  auto it = query.find(key);
  if (it == query.end()) return {};
  std::string v = it->second;
  query.erase(it);
  return v;
}

double SourceUri::take_number(const std::string& key, double fallback, double lo, double hi) {
  const std::string v = take(key);
  if (v.empty()) return fallback;
  double d = 0;
  const auto r = std::from_chars(v.data(), v.data() + v.size(), d);
  if (r.ec != std::errc() || r.ptr != v.data() + v.size() || !std::isfinite(d) || d < lo || d > hi)
    throw core::InputError("gaze source \"" + text + "\": " + key + "=" + v + " must be a number in [" +
                           std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return d;
}

double SourceUri::take_seconds(double fallback) {
  const std::string v = take("seconds");
  if (v.empty()) return fallback;
  double d = 0;
  const auto r = std::from_chars(v.data(), v.data() + v.size(), d);
  if (r.ec != std::errc() || r.ptr != v.data() + v.size() || !(d > 0 && d <= 1e6))
    throw core::InputError("gaze source \"" + text + "\": seconds=" + v +
                           " must be a length in (0, 1000000] s (leave seconds= out for endless gaze)");
  return d;
}

std::string SourceUri::rebuilt() const {
  std::string out = scheme + ":" + body;
  char sep = '?';
  for (const auto& [k, v] : query) {
    out += sep + k + "=" + v;
    sep = '&';
  }
  return out;
}

void SourceUri::finish() const {
  if (!query.empty())
    throw core::InputError("gaze source \"" + text + "\": unknown option \"" + query.begin()->first + "\"");
}

void apply_common_options(SourceUri& u, SourceOptions& opt) {
  opt.horizon_ns = std::llround(u.take_number("horizon_ms", static_cast<double>(opt.horizon_ns) * 1e-6, 0, 1000) * 1e6);
  if (auto m = u.take("predict"); !m.empty()) {
    try {
      opt.predict = parse_predict_mode(m);
    } catch (const core::InputError& e) {
      throw core::InputError("gaze source \"" + u.text + "\": " + e.what());
    }
  }
  opt.min_confidence = u.take_number("min_confidence", opt.min_confidence, 0, 1);
  if (auto f = u.take("filters"); !f.empty()) opt.filters = f;
  // The 2-D gaze geometry: the one place a URI sets it, so the layer's config and the
  // runtime's environment variable (both a URI) carry it too.
  if (auto sc = u.take("screen"); !sc.empty()) opt.screen = parse_screen(sc, "gaze source \"" + u.text + "\": screen");
}

// speed= and loop=, the replay keys of the timeline (docs/gaze.md). Every entry point that
// opens a recording takes and checks them; tools that walk every sample need not use them.
void take_timeline_keys(SourceUri& u, SourceOptions& opt) {
  opt.speed = u.take_number("speed", opt.speed, 1e-3, 1e3);
  const std::string loop = u.take("loop");
  if (!loop.empty() && loop != "0" && loop != "1")
    throw core::InputError("gaze source \"" + u.text + "\": loop must be 0 or 1");
  if (!loop.empty()) opt.loop = loop == "1";
}

namespace {
std::unique_ptr<SampleStream> open_raw_stream(SourceUri& u, const SourceOptions& opt);

std::unique_ptr<SampleStream> with_filters(std::unique_ptr<SampleStream> s, const SourceOptions& opt) {
  if (opt.filters.empty()) return s;
  return apply_filters(std::move(s), opt.filters, FilterParams{});
}
}  // namespace

std::unique_ptr<SampleStream> open_sample_stream(std::string_view uri, const SourceOptions& base) {
  SourceUri u = parse_source_uri(uri);
  SourceOptions opt = base;
  apply_common_options(u, opt);
  if (TrackerParams tracker; take_tracker_options(u, tracker))
    throw core::InputError("gaze source \"" + u.text +
                           "\": a tracker model delivers samples over time; it applies where gaze is read at a time "
                           "(render, view, the runtime, the layer), not to tools that walk every sample");
  return with_filters(open_raw_stream(u, opt), opt);
}

Recording open_recording(std::string_view uri, const SourceOptions& base) {
  SourceUri u = parse_source_uri(uri);
  if (u.scheme != "replay" && u.scheme != "hid-capture")
    throw core::InputError("\"" + u.text + "\": not a recording (replay:FILE, hid-capture:FILE or a file name)");
  if (u.body.empty()) throw core::InputError("gaze source \"" + u.text + "\": missing file name");
  Recording r;
  r.options = base;
  apply_common_options(u, r.options);
  take_timeline_keys(u, r.options);
  if (auto f = u.take("format"); !f.empty()) r.options.format = f;
  if (u.scheme == "hid-capture") r.options.format = format_name(Format::HidCapture);
  u.finish();
  auto reader = open_reader(u.body, r.options);
  r.reader = reader.get();
  r.stream = with_filters(std::move(reader), r.options);
  return r;
}

std::vector<std::string> recording_notes(std::string_view uri, const SourceOptions& opt) {
  SourceUri u = parse_source_uri(uri);
  if (u.scheme != "replay" && u.scheme != "hid-capture") return {};
  Recording r = open_recording(uri, opt);
  GazeSample s;
  while (r.reader->next(s)) {
  }
  return r.reader->stats().notes;
}

namespace {
std::unique_ptr<SampleStream> open_raw_stream(SourceUri& u, const SourceOptions& base) {
  SourceOptions opt = base;
  if ((u.scheme == "replay" || u.scheme == "synthetic") && !opt.raw_capture.empty())
    throw core::InputError("gaze source \"" + u.text + "\": raw capture needs a HID source (hid:, usb:, hid-emulated:)");
  if (u.scheme == "replay") {
    if (u.body.empty()) throw core::InputError("gaze source \"" + u.text + "\": missing file name");
    if (auto f = u.take("format"); !f.empty()) opt.format = f;
    take_timeline_keys(u, opt);
    u.finish();
    return open_reader(u.body, opt);
  }
  if (u.scheme == "synthetic") {
    SynthParams p;
    std::uint64_t seed = 0;
    const auto r = std::from_chars(u.body.data(), u.body.data() + u.body.size(), seed);
    if (u.body.empty() || r.ec != std::errc() || r.ptr != u.body.data() + u.body.size())
      throw core::InputError("gaze source \"" + u.text + "\": synthetic:SEED needs a non-negative integer seed");
    p.seed = seed;
    if (auto t = u.take("task"); !t.empty()) p.task = parse_synth_task(t);
    p.rate_hz = u.take_number("rate", p.rate_hz, 60, 1000);
    p.seconds = u.take_seconds(0);
    p.noise_deg = u.take_number("noise", p.noise_deg, 0, 10);
    p.noise_color = u.take_number("color", p.noise_color, 0, 0.98);
    p.dropout_per_s = u.take_number("dropouts", p.dropout_per_s, 0, 10);
    p.ipd_m = base.display.ipd_m;
    u.finish();
    return std::make_unique<SyntheticStream>(p);
  }
  return open_device_stream(u, opt);
}
}  // namespace

std::unique_ptr<GazeSource> open_gaze_source(std::string_view uri, const SourceOptions& base) {
  SourceUri u = parse_source_uri(uri);
  SourceOptions opt = base;
  apply_common_options(u, opt);
  if (u.scheme == "replay" || u.scheme == "hid-capture") take_timeline_keys(u, opt);
  TrackerParams tracker;
  const bool modelled = take_tracker_options(u, tracker);
  if (modelled && !opt.filters.empty())
    throw core::InputError("gaze source \"" + u.text + "\": filters cannot follow a tracker model");
  // The remaining options are validated by the stream itself.
  const std::string rebuilt = u.rebuilt();
  if (!modelled) return std::make_unique<TimelineSource>(open_sample_stream(rebuilt, opt), opt);
  // The URI's gaze is the true eye, read as it is; prediction applies to what the tracker delivers.
  SourceOptions truth = opt;
  truth.horizon_ns = 0;
  return std::make_unique<TrackerModel>(std::make_unique<TimelineSource>(open_sample_stream(rebuilt, truth), truth), tracker, opt);
}

}  // namespace fovea::devices
