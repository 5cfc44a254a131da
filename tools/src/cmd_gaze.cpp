// fovea gaze info|synth|convert|plot|record: recorded, synthetic and live gaze.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "canvas.hpp"
#include "command.hpp"
#include "fovea/core/error.hpp"
#include <chrono>
#include <filesystem>
#include <functional>
#include <thread>

#include "fovea/core/image.hpp"
#include "fovea/devices/analysis.hpp"
#include "fovea/devices/hid_stream.hpp"
#include "fovea/devices/readers.hpp"
#include "fovea/devices/synthetic.hpp"

namespace fovea::tools {

namespace dv = fovea::devices;

namespace {

const char* kHelp =
    "usage: fovea gaze <subcommand> ...\n"
    "  info FILE [--format F]          JSON summary: samples, validity, rate, events, dropped rows\n"
    "                                  (FILE: any replay format, a raw HID capture, or synthetic:SEED?seconds=S)\n"
    "  convert IN OUT [--format F]     any supported format -> the project's CSV (+ OUT.json)\n"
    "  synth --task T --seconds S OUT  synthetic gaze (--seed N --rate HZ --noise DEG --color C\n"
    "                                  --dropouts PER_S); tasks: reading search pursuit fixation-grid\n"
    "  plot FILE OUT.png               gaze over time and on the display, saccades marked\n"
    "  record --source URI --seconds S OUT [--raw CAPTURE] [--timeout S]\n"
    "                                  record any source (hid:, usb:, hid-emulated:LAYOUT, synthetic:,\n"
    "                                  replay); --raw writes the raw HID traffic (docs/hid.md)\n"
    "geometry for 2D formats: --display NAME|FILE (default small), --screen WxH@HFOVxVFOV\n"
    "  (e.g. 1920x1080@95x63: the raster and symmetric field of view the gaze coordinates refer to)\n"
    "--min-confidence C (default 0.6): samples below are marked lost\n"
    "formats: fovea pupil-core neon tobii-g3 eyelink-asc (auto-detected; see docs/gaze.md)\n";

const std::vector<std::string> kGeometryOpts = {"format", "display", "screen", "min-confidence"};

// "WxH@HFOVxVFOV" -> a View with a symmetric field of view.
core::View parse_screen(const std::string& s) {
  int w = 0, h = 0;
  double hf = 0, vf = 0;
  char tail = 0;
  if (std::sscanf(s.c_str(), "%dx%d@%lfx%lf%c", &w, &h, &hf, &vf, &tail) != 4 || w < 1 || h < 1 || w > 65536 ||
      h > 65536 || !(hf > 0 && hf < 179) || !(vf > 0 && vf < 179))
    throw core::InputError("--screen: expected WxH@HFOVxVFOV (pixels, degrees), e.g. 1920x1080@95x63; got \"" + s + "\"");
  return core::View(core::Fov::from_degrees(-hf / 2, hf / 2, vf / 2, -vf / 2), w, h);
}

dv::SourceOptions gaze_source_options(const Args& a) {
  dv::SourceOptions opt;
  opt.display = core::load_display(a.str("display", "small"));
  if (auto s = a.opt("screen")) opt.screen = parse_screen(*s);
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
  std::string format;
  bool reports_blinks = true;
};

Input open_input(const std::string& arg, const dv::SourceOptions& opt) {
  Input in;
  std::string uri = arg;
  if (uri.find(':') == std::string::npos) {
    std::FILE* f = std::fopen(arg.c_str(), "rb");
    char head[20] = {};
    if (f) {
      const std::size_t n = std::fread(head, 1, sizeof head - 1, f);
      head[n] = 0;
      std::fclose(f);
    }
    if (std::string(head).rfind("fovea-hid-capture", 0) == 0) uri = "hid-capture:" + arg;
  }
  if (uri.rfind("hid-capture:", 0) == 0) {
    auto cap = std::make_unique<dv::hid::HidCaptureStream>(uri.substr(12), opt);
    auto* raw = cap.get();
    in.stats = [raw] { return &raw->stats(); };
    in.format = "hid-capture";
    in.stream = std::move(cap);
    return in;
  }
  if (uri.rfind("synthetic:", 0) == 0) {
    if (uri.find("seconds=") == std::string::npos) throw core::InputError(arg + ": give the synthetic gaze a length (seconds=S)");
    in.stream = dv::open_sample_stream(uri, opt);
    in.format = "synthetic";
    return in;
  }
  if (uri.rfind("replay:", 0) == 0) uri = uri.substr(7);
  if (uri.find(':') != std::string::npos && !std::filesystem::exists(uri))
    throw core::InputError(arg + ": not a recording (live sources: use `fovea gaze record`)");
  auto reader = dv::open_reader(uri, opt);
  auto* raw = reader.get();
  in.stats = [raw] { return &raw->stats(); };
  in.format = dv::format_name(reader->format());
  in.reports_blinks = reader->reports_blinks();
  in.stream = std::move(reader);
  return in;
}

int cmd_info(const std::vector<std::string>& argv) {
  Args a(argv, kGeometryOpts, {}, 1);
  if (a.positional().size() != 1) throw core::InputError("gaze info needs FILE (see --help)");
  const dv::SourceOptions opt = gaze_source_options(a);
  Input in = open_input(a.positional()[0], opt);
  dv::SummaryParams sp;
  sp.infer_blinks = !in.reports_blinks;
  const dv::GazeSummary s = dv::summarize(*in.stream, sp);
  const dv::ReadStats* st = in.stats();
  if (s.tracked == 0)
    throw core::InputError(a.positional()[0] + ": no usable sample (" + std::to_string(s.samples) + " kept, " +
                           std::to_string(st ? st->dropped_total() : 0) + " dropped)");
  nlohmann::json j;
  j["format"] = in.format;
  j["samples"] = s.samples;
  j["valid_fraction"] = std::round(s.valid_fraction() * 1e6) / 1e6;
  j["rate_hz"] = std::round(s.rate_hz * 1e3) / 1e3;
  j["duration_s"] = std::round(s.duration_s * 1e6) / 1e6;
  j["dropped"] = nlohmann::json::object();
  if (st)
    for (const auto& [k, v] : st->dropped) j["dropped"][k] = v;
  j["fixations"] = s.fixations;
  j["saccades"] = s.saccades;
  j["blinks"] = s.blinks;
  std::cout << j.dump(2) << "\n";
  return 0;
}

int cmd_convert(const std::vector<std::string>& argv) {
  Args a(argv, kGeometryOpts, {}, 2);
  if (a.positional().size() != 2) throw core::InputError("gaze convert needs IN and OUT (see --help)");
  const dv::SourceOptions opt = gaze_source_options(a);
  const std::string& in_path = a.positional()[0];
  Input in = open_input(in_path, opt);
  nlohmann::json meta = {{"source", in_path}, {"source_format", in.format}, {"display", opt.display.name}};
  const core::View sv = opt.screen_view();
  meta["screen"] = {{"width", sv.width()}, {"height", sv.height()}};
  dv::FoveaCsvWriter w(a.positional()[1], meta.dump());
  dv::GazeSample s;
  std::uint64_t tracked = 0;
  while (in.stream->next(s)) {
    w.write(s);
    tracked += s.tracked();
  }
  if (tracked == 0) throw core::InputError(in_path + ": no usable sample; nothing written");
  w.finish();
  std::cerr << "converted " << w.samples() << " samples";
  if (const dv::ReadStats* st = in.stats()) {
    std::cerr << " (" << st->dropped_total() << " rows dropped";
    for (const auto& [k, v] : st->dropped) std::cerr << ", " << k << ": " << v;
    std::cerr << ")";
  }
  std::cerr << " -> " << a.positional()[1] << "\n";
  return 0;
}

int cmd_synth(const std::vector<std::string>& argv) {
  Args a(argv, {"task", "seconds", "seed", "rate", "noise", "color", "dropouts", "display"}, {}, 1);
  if (a.positional().size() != 1) throw core::InputError("gaze synth needs OUT (see --help)");
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
  const core::DisplayPreset display = core::load_display(a.str("display", "small"));
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

// Two panels: gaze angles over time (horizontal blue, vertical green; saccades shaded red,
// untracked time grey; grid every second and every 10°), and the gaze on the display
// (fixation samples dark, saccade samples red). Two streaming passes, bounded memory.
int cmd_plot(const std::vector<std::string>& argv) {
  Args a(argv, {"format", "display", "screen", "min-confidence", "width"}, {}, 2);
  if (a.positional().size() != 2) throw core::InputError("gaze plot needs FILE and OUT.png (see --help)");
  const dv::SourceOptions opt = gaze_source_options(a);
  Input in = open_input(a.positional()[0], opt);
  dv::SampleStream* reader = in.stream.get();
  dv::GazeSample s;
  core::TimeNs t_end = 0;
  double max_angle = 10;
  std::uint64_t tracked = 0;
  auto angles = [](const glm::dvec3& d) {
    return glm::dvec2(std::atan2(d.x, -d.z), std::atan2(d.y, std::hypot(d.x, d.z))) * (180.0 / M_PI);
  };
  while (reader->next(s)) {
    t_end = s.t_ns;
    if (s.tracked()) {
      ++tracked;
      const glm::dvec2 g = angles(s.combined.dir);
      max_angle = std::max({max_angle, std::abs(g.x), std::abs(g.y)});
    }
  }
  if (tracked == 0) throw core::InputError(a.positional()[0] + ": no usable sample to plot");
  max_angle = std::min(90.0, std::ceil(max_angle / 10) * 10);
  const int W = static_cast<int>(std::clamp(a.integer("width", 1200), 400L, 4000L));
  const int top = W * 3 / 10, margin = 20;
  const core::View view = opt.screen_view();
  const int disp_h = std::min(W * 6 / 10, static_cast<int>(double(W - 2 * margin) * view.height() / view.width()));
  const int disp_w = static_cast<int>(double(disp_h) * view.width() / view.height());
  Canvas c(W, top + disp_h + 3 * margin);
  const int px0 = margin, px1 = W - margin, py0 = margin, py1 = top;
  const double span = std::max<double>(static_cast<double>(t_end), 1.0);
  auto tx = [&](core::TimeNs t) { return px0 + (px1 - px0 - 1) * static_cast<double>(t) / span; };
  auto ay = [&](double deg) { return py0 + (py1 - py0 - 1) * (0.5 - 0.5 * deg / max_angle); };
  for (double t = 0; t <= span * 1e-9; t += 1.0) c.line(tx(core::TimeNs(t * 1e9)), py0, tx(core::TimeNs(t * 1e9)), py1 - 1, {0, 0, 0, 0.12f});
  for (double d = -max_angle; d <= max_angle; d += 10) c.line(px0, ay(d), px1 - 1, ay(d), {0, 0, 0, d == 0 ? 0.4f : 0.12f});
  c.frame(px0, py0, px1, py1, {0, 0, 0, 1});
  const int dx0 = (W - disp_w) / 2, dy0 = top + 2 * margin;
  c.rect(dx0, dy0, dx0 + disp_w, dy0 + disp_h, {0.93f, 0.93f, 0.93f, 1});
  c.frame(dx0, dy0, dx0 + disp_w, dy0 + disp_h, {0, 0, 0, 1});
  // Pass 2: events (shading) and traces.
  reader->rewind();
  dv::SummaryParams sp;
  sp.infer_blinks = !in.reports_blinks;
  dv::EventSegmenter seg(sp, [&](dv::EventSegmenter::Kind k, core::TimeNs t0, core::TimeNs t1) {
    if (k == dv::EventSegmenter::Kind::Saccade)
      c.rect(static_cast<int>(tx(t0)), py0 + 1, static_cast<int>(std::ceil(tx(t1))) + 1, py1 - 1, {0.9f, 0.1f, 0.1f, 0.25f});
  });
  bool have_prev = false;
  dv::GazeSample prev;
  glm::dvec2 prev_px{};
  bool prev_on = false;
  while (reader->next(s)) {
    seg.add(s);
    if (!s.tracked()) {
      c.rect(static_cast<int>(tx(s.t_ns)), py0 + 1, static_cast<int>(tx(s.t_ns)) + 1, py1 - 1, {0.5f, 0.5f, 0.5f, 0.3f});
      have_prev = false;
      continue;
    }
    const glm::dvec2 g = angles(s.combined.dir);
    if (have_prev) {
      const glm::dvec2 p = angles(prev.combined.dir);
      c.line(tx(prev.t_ns), ay(p.x), tx(s.t_ns), ay(g.x), {0.1f, 0.3f, 0.9f, 0.9f});
      c.line(tx(prev.t_ns), ay(p.y), tx(s.t_ns), ay(g.y), {0.1f, 0.6f, 0.2f, 0.9f});
    }
    const auto pix = view.dir_to_pixel(s.combined.dir);
    const bool on = pix.has_value();
    glm::dvec2 q{};
    if (on) q = glm::dvec2(dx0 + pix->x / view.width() * disp_w, dy0 + pix->y / view.height() * disp_h);
    const bool sacc = s.motion == dv::Motion::Saccade || (have_prev && core::angle_deg(prev.combined.dir, s.combined.dir) /
                                                                            std::max(1e-9, (s.t_ns - prev.t_ns) * 1e-9) >= sp.ivt.threshold_deg_s);
    if (on && prev_on && have_prev) c.line(prev_px.x, prev_px.y, q.x, q.y, sacc ? glm::vec4(0.9f, 0.1f, 0.1f, 0.6f) : glm::vec4(0.1f, 0.1f, 0.3f, 0.15f));
    if (on && !sacc) c.rect(int(q.x) - 1, int(q.y) - 1, int(q.x) + 2, int(q.y) + 2, {0.1f, 0.1f, 0.4f, 0.25f});
    prev = s;
    prev_px = q;
    prev_on = on;
    have_prev = true;
  }
  seg.finish();
  core::write_png(a.positional()[1], c.img);
  std::cerr << "wrote " << a.positional()[1] << " (" << c.img.width << "x" << c.img.height << ")\n";
  return 0;
}

// Records any source into the project's format; HID sources can also write the raw traffic.
int cmd_record(const std::vector<std::string>& argv) {
  Args a(argv, {"source", "seconds", "raw", "display", "screen", "timeout"}, {}, 1);
  if (a.positional().size() != 1 || !a.has("source")) throw core::InputError("gaze record needs --source URI and OUT (see --help)");
  dv::SourceOptions opt = gaze_source_options(a);
  opt.raw_capture = a.str("raw", "");
  const double seconds = a.num("seconds", 5);
  if (!(seconds > 0)) throw core::InputError("--seconds must be positive");
  const double timeout = a.num("timeout", seconds + 5);  // wall clock, for live devices
  auto stream = dv::open_sample_stream(a.str("source", ""), opt);
  auto* hid = dynamic_cast<dv::hid::HidGazeStream*>(stream.get());
  const nlohmann::json meta = {{"display", opt.display.name}, {"source", stream->describe()}};
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

}  // namespace fovea::tools
