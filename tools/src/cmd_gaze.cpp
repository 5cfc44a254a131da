// fovea gaze info|synth|convert|plot|record: recorded, synthetic and live gaze.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "figures.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/output_path.hpp"
#include <chrono>
#include <filesystem>
#include <functional>
#include <thread>

#include "fovea/core/image.hpp"
#include "fovea/devices/analysis.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "fovea/devices/readers.hpp"
#include "fovea/devices/screen.hpp"
#include "fovea/devices/synthetic.hpp"

namespace fovea::tools::cmd_gaze {

namespace dv = fovea::devices;

namespace {

const char* kHelp =
    "usage: fovea gaze <subcommand> ...\n"
    "  info FILE [--format F] [--events]\n"
    "                                  JSON summary: samples, validity, rate, events, dropped rows,\n"
    "                                  data quality (RMS-S2S, STD, data loss); --events lists each\n"
    "                                  fixation, saccade and blink with its times\n"
    "                                  (FILE: any replay format, a raw HID capture, or synthetic:SEED?seconds=S)\n"
    "  convert IN OUT [--format F]     any supported format -> the project's CSV (+ OUT.json)\n"
    "  synth --task T --seconds S OUT  synthetic gaze (--seed N --rate HZ --noise DEG --color C\n"
    "                                  --dropouts PER_S); tasks: reading search pursuit fixation-grid\n"
    "  plot FILE OUT.png [--from S --to S --width PX]\n"
    "                                  gaze angles against time and the scanpath on the screen,\n"
    "                                  drawn by matplotlib as OUT.png and OUT.svg from OUT.json\n"
    "                                  (the data; docs/figures.md); --from/--to: a time window (s)\n"
    "  record --source URI --seconds S OUT [--raw CAPTURE] [--timeout S]\n"
    "                                  record any source (hid:, usb:, hid-emulated:LAYOUT, synthetic:,\n"
    "                                  replay); --raw writes the raw HID traffic (docs/hid.md)\n"
    "geometry for 2D formats: --display NAME|FILE (default small), --screen WxH@HFOVxVFOV or\n"
    "  WxH@SWxSHmm@Dmm (screen size and eye distance; also the URI key screen=)\n"
    "  (e.g. 1920x1080@95x63: the raster and symmetric field of view the gaze coordinates refer to)\n"
    "--min-confidence C (default 0.6): samples below are marked lost\n"
    "formats: fovea pupil-core neon tobii-g3 eyelink-asc (auto-detected; see docs/gaze.md)\n";

const std::vector<std::string> kGeometryOpts = {"format", "display", "screen", "min-confidence"};

dv::SourceOptions gaze_source_options(const Args& a) {
  dv::SourceOptions opt;
  opt.display = core::load_display(a.str("display", core::kDefaultDisplay));
  if (auto s = a.opt("screen")) opt.screen = dv::parse_screen(*s, "--screen");
  opt.format = a.str("format", "");
  opt.min_confidence = a.num("min-confidence", opt.min_confidence);
  if (!(opt.min_confidence >= 0 && opt.min_confidence <= 1)) throw core::InputError("--min-confidence must be in [0, 1]");
  return opt;
}

// A recording to walk: a file in any replay format, a raw HID capture (file or
// hid-capture:FILE), or synthetic:SEED?…&seconds=S. Live sources belong to `gaze record`.
struct Input {
  std::unique_ptr<dv::SampleStream> stream;
  std::function<const dv::ReadStats*()> stats = [] { return nullptr; };
  dv::GazeReader* reader = nullptr;  // replay formats: messages, time origin
  dv::SourceOptions options;         // after the URI's own keys (screen=, ...)
  std::string format;
  bool reports_blinks = true;
};

Input open_input(const std::string& arg, const dv::SourceOptions& opt) {
  Input in;
  in.options = opt;
  const std::string& uri = arg;
  if (uri.rfind("synthetic:", 0) == 0) {
    if (uri.find("seconds=") == std::string::npos) throw core::InputError(arg + ": give the synthetic gaze a length (seconds=S)");
    in.stream = dv::open_sample_stream(uri, opt);
    in.format = "synthetic";
    return in;
  }
  // Every recording, raw HID captures included (detected by their first line, plain or gzip).
  const bool capture = uri.rfind("hid-capture:", 0) == 0;
  const std::string file = uri.rfind("replay:", 0) == 0 ? uri.substr(7) : uri;
  const std::string path = file.substr(0, file.find('?'));
  if (!capture && path.find(':') != std::string::npos && !std::filesystem::exists(path))
    throw core::InputError(arg + ": not a recording (live sources: use `fovea gaze record`)");
  dv::Recording rec = dv::open_recording(capture ? uri : "replay:" + file, opt);
  auto* raw = rec.reader;
  in.stats = [raw] { return &raw->stats(); };
  in.reader = raw;
  in.options = rec.options;
  in.format = dv::format_name(raw->format());
  in.reports_blinks = raw->reports_blinks();
  in.stream = std::move(rec.stream);
  return in;
}

// What the reader noticed about the data (truncated gzip, gaze off the display, ...).
void print_notes(const Input& in) {
  if (const dv::ReadStats* st = in.stats())
    for (const auto& n : st->notes) std::cerr << "warning: " << n << "\n";
}

// Rounded to `decimals` places (dividing by a power of ten prints cleanly; multiplying by
// 1e-5 would not).
double round_to(double v, int decimals) {
  const double p = std::pow(10.0, decimals);
  return std::round(v * p) / p;
}

int cmd_info(const std::vector<std::string>& argv) {
  Args a(argv, kGeometryOpts, {"events"}, 1);
  if (a.positional().size() != 1) throw core::InputError("gaze info needs FILE (see --help)");
  const dv::SourceOptions opt = gaze_source_options(a);
  Input in = open_input(a.positional()[0], opt);
  dv::SummaryParams sp;
  sp.infer_blinks = !in.reports_blinks;
  nlohmann::json events = nlohmann::json::array();
  dv::EventSegmenter::Callback on_event;
  if (a.has("events"))
    on_event = [&](const dv::GazeEvent& e) {
      nlohmann::json o = {{"type", dv::event_kind_name(e.kind)},
                          {"start_ns", e.start_ns},
                          {"end_ns", e.end_ns},
                          {"duration_ms", round_to(static_cast<double>(e.end_ns - e.start_ns) * 1e-6, 3)}};
      if (e.kind != dv::GazeEvent::Kind::Fixation) o["amplitude_deg"] = round_to(e.amplitude_deg, 3);
      if (e.kind == dv::GazeEvent::Kind::Fixation) {
        o["rms_s2s_deg"] = round_to(e.rms_s2s_deg, 5);
        o["std_deg"] = round_to(e.std_deg, 5);
      }
      events.push_back(std::move(o));
    };
  const dv::GazeSummary s = dv::summarize(*in.stream, sp, on_event);
  const dv::ReadStats* st = in.stats();
  print_notes(in);
  if (s.tracked == 0)
    throw core::InputError(a.positional()[0] + ": no usable sample (" + std::to_string(s.samples) + " kept, " +
                           std::to_string(st ? st->dropped_total() : 0) + " dropped)");
  nlohmann::json j;
  j["format"] = in.format;
  j["samples"] = s.samples;
  j["valid_fraction"] = round_to(s.valid_fraction(), 6);
  j["rate_hz"] = round_to(s.rate_hz, 3);
  j["duration_s"] = round_to(s.duration_s, 6);
  j["dropped"] = nlohmann::json::object();
  if (st)
    for (const auto& [k, v] : st->dropped) j["dropped"][k] = v;
  j["fixations"] = s.fixations;
  j["saccades"] = s.saccades;
  j["blinks"] = s.blinks;
  const dv::DataQuality& q = s.quality;
  j["data_quality"] = {{"rms_s2s_deg", round_to(q.rms_s2s_deg, 5)},
                       {"std_deg", round_to(q.std_deg, 5)},
                       {"fixations_measured", q.fixations_measured},
                       {"data_loss", round_to(q.data_loss, 6)},
                       {"data_loss_excluding_blinks", round_to(q.data_loss_excluding_blinks, 6)}};
  if (st && !st->notes.empty()) j["notes"] = st->notes;
  if (a.has("events")) j["events"] = std::move(events);
  std::cout << j.dump(2) << "\n";
  return 0;
}

// Messages of a recording (EyeLink MSG, Neon events) collected while it is read, written
// next to the converted file as OUT.events.csv on the output's timeline.
class MessageLog {
 public:
  explicit MessageLog(dv::GazeReader* reader) {
    if (reader) reader->set_message_sink([this](const dv::RecordingMessage& m) { add(m); });
  }
  std::size_t size() const { return messages_.size(); }
  // t_ns = device time - origin (negative for messages before the first sample).
  void write(const std::string& path, core::TimeNs origin) const {
    std::string csv = "t_ns,device_time_ns,kind,text\n";
    for (const auto& m : messages_) {
      std::string text;  // CSV quoting: the text may hold commas and quotes
      for (char c : m.text) text += c == '"' ? std::string("\"\"") : std::string(1, c);
      core::TimeNs t = 0;
      if (__builtin_sub_overflow(m.device_time_ns, origin, &t)) continue;
      csv += std::to_string(t) + "," + std::to_string(m.device_time_ns) + "," + m.kind + ",\"" + text + "\"\n";
    }
    core::write_file_atomic(path, csv);
  }
  std::uint64_t skipped() const { return skipped_; }

 private:
  void add(const dv::RecordingMessage& m) {
    constexpr std::size_t kMaxBytes = 64 << 20;  // messages are few; a hostile file must not fill memory
    if (bytes_ + m.text.size() > kMaxBytes) {
      ++skipped_;
      return;
    }
    bytes_ += m.text.size();
    messages_.push_back(m);
  }
  std::vector<dv::RecordingMessage> messages_;
  std::size_t bytes_ = 0;
  std::uint64_t skipped_ = 0;
};

int cmd_convert(const std::vector<std::string>& argv) {
  Args a(argv, kGeometryOpts, {}, 2);
  if (a.positional().size() != 2) throw core::InputError("gaze convert needs IN and OUT (see --help)");
  const dv::SourceOptions opt = gaze_source_options(a);
  const std::string& in_path = a.positional()[0];
  const std::string& out_path = a.positional()[1];
  core::prepare_output_file(out_path, "OUT");
  Input in = open_input(in_path, opt);
  MessageLog log(in.reader);
  nlohmann::json meta = {{"source", in_path}, {"source_format", in.format}, {"display", in.options.display.name}};
  const core::View sv = in.options.screen_view();
  meta["screen"] = {{"width", sv.width()},
                    {"height", sv.height()},
                    {"hfov_deg", round_to((sv.fov().angle_right - sv.fov().angle_left) * 180 / M_PI, 6)},
                    {"vfov_deg", round_to((sv.fov().angle_up - sv.fov().angle_down) * 180 / M_PI, 6)}};
  dv::GazeSample s;
  std::uint64_t tracked = 0;
  bool have_first = false;
  core::TimeNs first_device = 0;
  auto w = std::make_unique<dv::FoveaCsvWriter>(out_path, meta.dump());
  while (in.stream->next(s)) {
    if (!have_first) {
      have_first = true;
      first_device = s.device_time_ns;
    }
    w->write(s);
    tracked += s.tracked();
  }
  print_notes(in);
  if (tracked == 0) throw core::InputError(in_path + ": no usable sample; nothing written");
  // The original time base: t_ns = device time - t0, on the source's clock.
  const core::TimeNs origin = in.reader ? in.reader->time_origin_ns() : first_device;
  meta["time_base"] = {{"t0_device_time_ns", origin},
                       {"device_clock", in.reader ? dv::device_clock_name(in.reader->format()) : in.format}};
  if (in.reader) meta["events_file"] = std::filesystem::path(out_path + ".events.csv").filename().string();
  w->set_metadata(meta.dump());
  w->finish();
  if (in.reader) log.write(out_path + ".events.csv", origin);
  std::cerr << "converted " << w->samples() << " samples";
  if (const dv::ReadStats* st = in.stats()) {
    std::cerr << " (" << st->dropped_total() << " rows dropped";
    for (const auto& [k, v] : st->dropped) std::cerr << ", " << k << ": " << v;
    std::cerr << ")";
  }
  if (in.reader) std::cerr << ", " << log.size() << " messages";
  if (log.skipped()) std::cerr << " (" << log.skipped() << " skipped: over 64 MiB of text)";
  std::cerr << " -> " << out_path << "\n";
  return 0;
}

int cmd_synth(const std::vector<std::string>& argv) {
  Args a(argv, {"task", "seconds", "seed", "rate", "noise", "color", "dropouts", "display"}, {}, 1);
  if (a.positional().size() != 1) throw core::InputError("gaze synth needs OUT (see --help)");
  core::prepare_output_file(a.positional()[0], "OUT");
  dv::SynthParams p;
  p.task = dv::parse_synth_task(a.str("task", "search"));
  p.seconds = a.num("seconds", 5);
  if (!(p.seconds > 0)) throw core::InputError("--seconds must be positive");
  const long seed = a.integer("seed", 1);
  if (seed < 0) throw core::InputError("--seed must be non-negative");
  p.seed = static_cast<std::uint64_t>(seed);
  p.rate_hz = a.num("rate", p.rate_hz);
  p.noise_deg = a.num("noise", p.noise_deg);
  p.noise_color = a.num("color", p.noise_color);
  p.dropout_per_s = a.num("dropouts", p.dropout_per_s);
  const core::DisplayPreset display = core::load_display(a.str("display", core::kDefaultDisplay));
  p.ipd_m = display.ipd_m;
  dv::SyntheticStream stream(p);
  std::ostringstream cmd;
  cmd << "fovea gaze synth --task " << dv::synth_task_name(p.task) << " --seconds " << p.seconds << " --seed " << p.seed
      << " --rate " << p.rate_hz << " --noise " << p.noise_deg << " --color " << p.noise_color << " --dropouts "
      << p.dropout_per_s << " --display " << display.name;
  const nlohmann::json meta = {{"display", display.name},
                               {"generator", cmd.str()},
                               {"synthetic", {{"seed", p.seed},
                                              {"task", dv::synth_task_name(p.task)},
                                              {"rate_hz", p.rate_hz},
                                              {"seconds", p.seconds},
                                              {"noise_deg_rms", p.noise_deg},
                                              {"noise_color", p.noise_color},
                                              {"dropouts_per_s", p.dropout_per_s}}}};
  dv::FoveaCsvWriter w(a.positional()[0], meta.dump());
  dv::GazeSample s;
  while (stream.next(s)) w.write(s);
  w.finish();
  std::cerr << "wrote " << w.samples() << " samples -> " << a.positional()[0] << "\n";
  return 0;
}

// ---- plot ------------------------------------------------------------------------------
// The figure's data, OUT's stem + .json: per sample (every stride-th in the window, at most
// kMaxPlotSamples) the time, the horizontal and vertical gaze angle (deg; + right, + up;
// null when untracked), the point on the screen raster (px; null when off it) and whether it
// is in a saccade; the I-VT saccades and the untracked stretches as time intervals. Drawn by
// tools/plots/gaze.py as OUT.png and OUT.svg: angles against time with saccades shaded and
// lines broken where the eye was untracked or the recording has a gap, and the scanpath.
constexpr std::uint64_t kMaxPlotSamples = 200000;

int cmd_plot(const std::vector<std::string>& argv) {
  Args a(argv, {"format", "display", "screen", "min-confidence", "width", "from", "to"}, {}, 2);
  if (a.positional().size() != 2) throw core::InputError("gaze plot needs FILE and OUT.png (see --help)");
  const std::string out_png = a.positional()[1];
  core::prepare_output_file(out_png, "OUT.png");
  const dv::SourceOptions opt = gaze_source_options(a);
  const double from_s = a.num("from", 0), to_s = a.num("to", 9.2e9);
  if (!(from_s >= 0 && to_s > from_s && to_s <= 9.2e9))
    throw core::InputError("--from/--to: need 0 <= FROM < TO (seconds from the first sample)");
  const long width = std::clamp(a.integer("width", 1200), 400L, 4000L);
  const auto from_ns = static_cast<core::TimeNs>(from_s * 1e9), to_ns = static_cast<core::TimeNs>(to_s * 1e9);
  Input in = open_input(a.positional()[0], opt);
  dv::SampleStream* reader = in.stream.get();
  dv::GazeSample s;
  std::uint64_t tracked = 0, in_range = 0;
  std::vector<double> steps;  // the first sample intervals: the recording's sample period
  core::TimeNs last = -1;
  auto angles = [](const glm::dvec3& d) {
    return glm::dvec2(std::atan2(d.x, -d.z), std::atan2(d.y, std::hypot(d.x, d.z))) * (180.0 / M_PI);
  };
  auto in_window = [&](core::TimeNs t) { return t >= from_ns && t <= to_ns; };
  while (reader->next(s)) {
    if (!in_window(s.t_ns)) continue;
    ++in_range;
    tracked += s.tracked();
    if (last >= 0 && s.t_ns > last && steps.size() < 10000) steps.push_back(double(s.t_ns - last) * 1e-9);
    last = s.t_ns;
  }
  print_notes(in);
  if (tracked == 0) throw core::InputError(a.positional()[0] + ": no usable sample to plot" + (a.has("from") || a.has("to") ? " in --from/--to" : ""));
  std::sort(steps.begin(), steps.end());
  const std::uint64_t stride = std::max<std::uint64_t>(1, (in_range + kMaxPlotSamples - 1) / kMaxPlotSamples);
  const core::View view = in.options.screen_view();

  // Pass 2: the samples, the saccades and the untracked stretches.
  reader->rewind();
  dv::SummaryParams sp;
  sp.infer_blinks = !in.reports_blinks;
  nlohmann::json saccades = nlohmann::json::array(), untracked = nlohmann::json::array();
  dv::EventSegmenter seg(sp, [&](const dv::GazeEvent& e) {
    if (e.kind == dv::GazeEvent::Kind::Saccade) saccades.push_back({e.start_ns * 1e-9, e.end_ns * 1e-9});
  });
  nlohmann::json t = nlohmann::json::array(), h = t, v = t, x = t, y = t, sacc_flag = t;
  core::TimeNs lost_since = -1;  // start of the untracked stretch (times in the window are >= 0)
  bool have_prev = false;
  dv::GazeSample prev;
  std::uint64_t index = 0;
  while (reader->next(s)) {
    if (!in_window(s.t_ns)) continue;
    seg.add(s);
    const bool keep = index++ % stride == 0;
    if (!s.tracked()) {
      if (lost_since < 0) lost_since = s.t_ns;
      have_prev = false;
      if (keep) {
        t.push_back(round_to(s.t_ns * 1e-9, 6));
        for (auto* col : {&h, &v, &x, &y}) col->push_back(nullptr);
        sacc_flag.push_back(0);
      }
      continue;
    }
    if (lost_since >= 0) untracked.push_back({lost_since * 1e-9, s.t_ns * 1e-9});
    lost_since = -1;
    const bool sacc = s.motion == dv::Motion::Saccade || (have_prev && core::angle_deg(prev.combined.dir, s.combined.dir) /
                                                                            std::max(1e-9, (s.t_ns - prev.t_ns) * 1e-9) >= sp.ivt.threshold_deg_s);
    prev = s;
    have_prev = true;
    if (!keep) continue;
    const glm::dvec2 g = angles(s.combined.dir);
    const auto pix = view.dir_to_pixel(s.combined.dir);
    t.push_back(round_to(s.t_ns * 1e-9, 6));
    h.push_back(round_to(g.x, 4));
    v.push_back(round_to(g.y, 4));
    x.push_back(pix ? nlohmann::json(round_to(pix->x, 2)) : nlohmann::json(nullptr));
    y.push_back(pix ? nlohmann::json(round_to(pix->y, 2)) : nlohmann::json(nullptr));
    sacc_flag.push_back(sacc ? 1 : 0);
  }
  if (lost_since >= 0) untracked.push_back({lost_since * 1e-9, last * 1e-9});
  seg.finish();

  const std::filesystem::path stem = std::filesystem::path(out_png).replace_extension();
  const std::string data_path = stem.string() + ".json";
  nlohmann::ordered_json j;
  j["figure"] = "gaze";
  j["file"] = stem.filename().string();
  j["source"] = std::filesystem::path(a.positional()[0]).filename().string();
  j["width_px"] = width;
  j["screen"] = {{"width", view.width()},
                 {"height", view.height()},
                 {"fov_x_deg", (view.fov().angle_right - view.fov().angle_left) * 180 / M_PI},
                 {"fov_y_deg", (view.fov().angle_up - view.fov().angle_down) * 180 / M_PI}};
  j["sample_period_s"] = steps.empty() ? 0.0 : steps[steps.size() / 2];
  j["stride"] = stride;
  j["saccades"] = saccades;
  j["untracked"] = untracked;
  j["t"] = t, j["h"] = h, j["v"] = v, j["x"] = x, j["y"] = y, j["saccade"] = sacc_flag;
  core::write_file_atomic(data_path, j.dump() + "\n");
  if (draw_figures("gaze", data_path, std::cerr))
    std::cerr << "wrote " << stem.string() << ".png and .svg (data: " << data_path << ")\n";
  else
    std::cerr << "wrote " << data_path << "\n";
  return 0;
}

// Records any source into the project's format; HID sources can also write the raw traffic.
int cmd_record(const std::vector<std::string>& argv) {
  Args a(argv, {"source", "seconds", "raw", "display", "screen", "timeout"}, {}, 1);
  if (a.positional().size() != 1 || !a.has("source")) throw core::InputError("gaze record needs --source URI and OUT (see --help)");
  core::prepare_output_file(a.positional()[0], "OUT");
  dv::SourceOptions opt = gaze_source_options(a);
  opt.raw_capture = a.str("raw", "");
  const double seconds = a.num("seconds", 5);
  if (!(seconds > 0)) throw core::InputError("--seconds must be positive");
  const double timeout = a.num("timeout", seconds + 5);  // wall clock, for live devices
  auto stream = dv::open_sample_stream(a.str("source", ""), opt);
  auto* hid = dynamic_cast<dv::hid::HidGazeStream*>(stream.get());
  nlohmann::json meta = {{"display", opt.display.name}, {"source", stream->describe()}};
  dv::FoveaCsvWriter w(a.positional()[0], meta.dump());
  const auto start = std::chrono::steady_clock::now();
  const auto limit = static_cast<core::TimeNs>(seconds * 1e9);
  bool have_first = false;
  core::TimeNs first = 0;
  dv::GazeSample s;
  std::uint64_t tracked = 0;
  for (;;) {
    if (!stream->next(s)) {
      if (!stream->live() || (hid && hid->finished())) break;
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > timeout) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    if (!have_first) {
      have_first = true;
      first = s.t_ns;
      // The original time base: the first sample's time on the source's timeline (live
      // devices: host monotonic clock), its device and its host receive time.
      meta["time_base"] = {{"t0_source_ns", s.t_ns}, {"t0_device_time_ns", s.device_time_ns}, {"t0_host_time_ns", s.host_time_ns}};
      w.set_metadata(meta.dump());
    }
    s.t_ns -= first;
    if (s.t_ns >= limit) break;
    w.write(s);
    tracked += s.tracked();
  }
  if (hid) {
    hid->stop();
    const auto st = hid->stats();
    std::cerr << "reports " << st.reports << ", samples " << st.samples << ", status " << st.status_reports
              << ", transport errors " << st.transport_errors << ", clock drift " << st.clock_drift_ppm << " ppm";
    for (const auto& [k, v] : st.dropped) std::cerr << ", " << k << ": " << v;
    for (const auto& n : st.notes) std::cerr << "\n  note: " << n;
    std::cerr << "\n";
  }
  if (tracked == 0) throw core::InputError(stream->describe() + ": no usable sample recorded; nothing written");
  w.finish();
  std::cerr << "recorded " << w.samples() << " samples -> " << a.positional()[0] << "\n";
  return 0;
}

int run(std::vector<std::string> args) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::cout << kHelp;
    return args.empty() ? 2 : 0;
  }
  const std::string sub = args[0];
  args.erase(args.begin());
  for (const auto& s : args)
    if (s == "--help" || s == "-h") {
      std::cout << kHelp;
      return 0;
    }
  if (sub == "info") return cmd_info(args);
  if (sub == "convert") return cmd_convert(args);
  if (sub == "synth") return cmd_synth(args);
  if (sub == "record") return cmd_record(args);
  if (sub == "plot") return cmd_plot(args);
  throw core::InputError("unknown gaze subcommand \"" + sub + "\" (info, convert, synth, plot, record)");
}

}  // namespace

FOVEA_COMMAND(gaze_cmd, "gaze", "recorded, synthetic and live gaze: info, convert, synth, plot, record", run);

}  // namespace fovea::tools::cmd_gaze
