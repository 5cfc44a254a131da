// fovea latency: the latency harness. A true eye behind a modelled eye tracker, the real
// foveated pipeline, and the display model, in virtual time; or the timing records of an
// OpenXR session. Reports latency distributions and the foveal error they cause.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/core/duration.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/output_path.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/metrics.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "fovea/xrcommon/timing_writer.hpp"
#include "latency/analysis.hpp"
#include "reference_cache.hpp"
#include "render_setup.hpp"

namespace fovea::tools::cmd_latency {
namespace {

namespace fs = std::filesystem;

constexpr const char* kDefaultGaze = "synthetic:1?task=search&rate=1000&noise=0&dropouts=0";

constexpr const char* kHelpHead = R"(usage: fovea latency [options]
       fovea latency --records FILE.jsonl [--out DIR]

Measures latency the way it reaches the eye, in virtual time (reproducible): a true eye
(synthetic saccades or a recording) behind a modelled eye tracker; an application paced by
the display model that reads the tracker when xrWaitFrame returns, renders with the real
foveated pipeline on the Vulkan device and submits; the display model shows each frame at
the first vsync it makes (later frames are counted as missed, the previous frame stays) and
lights each eye and panel region. Per frame a timing record (docs/openxr.md), with the true
gaze at photon time; per vsync the foveal error (true gaze to the fovea on the panel).
Then the same frames with each gaze compensation mode (the foveal error after saccades
with and without prediction), and with injected latency (extra tracker delay) against
foveal error and fovea quality. With --records: the same analysis of an OpenXR session's timing records
(the runtime's timing.jsonl, the layer's layer_timing.jsonl, a render's frame_times.jsonl).

Prints the summary JSON on stdout; writes into --out:
  records.jsonl        the simulation's timing records (virtual clock, from 0)
  summary.json         the summary
  figures.json         the data of the figures below, drawn by matplotlib as .png and
                       .svg (docs/figures.md; redraw: fovea plot DIR/figures.json)
  latency              CDFs of tracker delay, gaze-to-photon, motion-to-photon
  stages               CDFs of each stage's CPU and GPU time
  foveal_error         foveal error at photon time over time, saccade onsets marked
  sweep_error          injected latency vs foveal error (median, p95, n per point)
  sweep_quality        injected latency vs tone-mapped PSNR where the user looks after
                       saccades (--quality-frames > 0; frames and saccades per point)
  sweep_flip           the same with HDR-FLIP

  --scene S             cornell | furnace | glossy-spheres | stereo-occluders | default,
                        or a .gltf/.glb/.obj file [default]
  --display NAME|FILE   display preset or JSON: raster, FOV, refresh [small]
  --gaze SRC            the true eye: recording or synthetic:<seed>[?...] (docs/gaze.md)
                        [synthetic:1?task=search&rate=1000&noise=0&dropouts=0]
)";
constexpr const char* kHelpTail = R"(  --tracker PRESET      eye-tracker model preset: fove0 | ideal [fove0]
  --tracker-delay T     delay from measurement to delivery [preset's]
  --jitter T            the tracker's extra delivery delay, uniform in [0, T] [preset's]
                        (not the grid's: its sub-cell jitter is on)
  --rate HZ             tracker sample rate [preset's]
  --predict MODE        gaze compensation of the main run: none | linear | landing (the
                        delivered samples predicted to each frame's display time; docs/gaze.md)
                        [none]
  --seconds S           scenario length [2]
  --render-time T       fixed render cost per frame instead of the measured CPU time
                        (reproducible runs); the pipeline still renders every frame
  --no-main-render      with --render-time: the main run's frames are not rendered (its
                        records have no stage times; the comparisons and the sweep are the
                        same), for a quality sweep alone at a display where frames are dear
  --scan-out M          global | rolling [global]
  --persistence T       how long a row stays lit [0]
  --inject-latency LIST injected latencies for the sweep, e.g. 0,25ms,50,100 ("none": no
                        sweep) [0,25,50,75,100]
  --quality-frames N    fovea quality of each sweep point at the N frames shown after the
                        end of every saccade of at least 5 deg, each rendered from 3 frames
                        before its onset on (0: no quality) [8]
  --quality-at LIST     the injected latencies whose quality is measured, a subset of
                        --inject-latency ("all") [all]
  --quality-radius DEG  quality within this angle of the true gaze at photon time [2.5]
  --reference-spp N     at most N samples per pixel of the converged reference [64]
  --reference-error X   stop the reference at this per-pixel relative standard error [0.02]
  --reference-cache DIR|off  where references are cached, shared with `fovea render` and
                        `fovea reference` [$XDG_CACHE_HOME/fovea/references]
  --records FILE        analyse timing records instead of simulating
  --out DIR             output directory [out/latency]
  --quiet               no progress on stderr
  --help                this text
Times take a unit, ms or us (also ns, s); a bare number is milliseconds.

Exit status: 0 on success, 2 on invalid arguments or input files, 1 on other errors.
)";

std::vector<core::TimeNs> parse_latency_list(const std::string& s) {
  std::vector<core::TimeNs> out;
  if (s == "none") return out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) {
    const core::TimeNs t = core::parse_duration_ns(item, "--inject-latency");
    if (t > core::ms_to_ns(1000)) throw core::InputError("--inject-latency: " + item + " is over 1 s");
    out.push_back(t);
  }
  if (out.empty()) throw core::InputError("--inject-latency: empty list (\"none\" for no sweep)");
  return out;
}

std::vector<xrcommon::TimingRecord> read_records(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw core::InputError(path + ": cannot open");
  std::vector<xrcommon::TimingRecord> out;
  std::string line;
  for (long n = 1; std::getline(in, line); ++n)
    if (line.find_first_not_of(" \t\r") != std::string::npos)
      out.push_back(xrcommon::parse_timing_record(line, path + ":" + std::to_string(n)));
  if (out.empty()) throw core::InputError(path + ": no timing records");
  return out;
}

void finish(const fs::path& out, nlohmann::json summary, const std::vector<std::string>& plots) {
  summary["plots"] = plots;
  core::write_file_atomic((out / "summary.json").string(), summary.dump(2) + "\n");
  std::cout << summary.dump(2) << "\n";
}

int run_records(const Args& args, const fs::path& out) {
  const std::string path = *args.opt("records");
  const std::vector<xrcommon::TimingRecord> records = read_records(path);
  nlohmann::json j = latency::summarize(records, nullptr);
  j["mode"] = "records";
  j["records"] = path;
  j["source"] = records.front().source;
  j["clock"] = xrcommon::time_base_name(records.front().clock);
  finish(out, j, sweep::write_charts(out.string(), "figures.json",
                                     latency::plots(records, nullptr, "records: " + fs::path(path).filename().string())));
  return 0;
}

// The quality where the user looks after saccades, of frames rendered for `sim`'s gaze: for
// every saccade of at least 5 deg the pipeline renders from `warm` frames before its onset
// on (from a reset history) and scores the `count` frames shown first after its end, where
// latency decides whether the fovea is there yet: tone-mapped PSNR, HDR-FLIP and LDR-FLIP
// within `radius_deg` of the true gaze at the frame's photon time, against the converged
// reference (left eye). Frame f is always rendered with seed f, so sweep points differ by
// their gaze, not by their noise.
struct Quality {
  double psnr = 0, hdr_flip = 0, ldr_flip = 0;
  int frames = 0, saccades = 0;
};
Quality fovea_quality(pipeline::FramePipeline& pipe, const std::array<core::Pose, 2>& poses,
                      const latency::Simulation& sim, std::size_t count, std::size_t warm, double radius_deg,
                      const core::Image& reference, const core::ViewMask& lens) {
  Quality q;
  const core::View view = pipe.view(core::Eye::Left);
  const auto first_shown_from = [&](core::TimeNs t) {
    std::size_t f = 0;
    while (f < sim.records.size() && (*sim.records[f].photon_ns)[0].mid < t) ++f;
    return f;
  };
  for (const latency::Saccade& s : sim.saccades) {
    if (s.amplitude_deg < 5) continue;
    const std::size_t onset = first_shown_from(s.onset_ns), landed = first_shown_from(s.offset_ns);
    if (landed + count > sim.frames.size()) continue;  // its window runs past the end
    ++q.saccades;
    pipe.reset();
    for (std::size_t f = onset > warm ? onset - warm : 0; f < landed + count; ++f) {
      pipe.render(poses, sim.frames[f].fovea, std::uint32_t(f));
      const auto& truth = sim.frames[f].truth[0];
      if (f < landed || !truth) continue;
      const std::vector<float> ecc = core::eccentricity_map(view, *truth);
      std::vector<float> w(ecc.size());
      for (std::size_t i = 0; i < ecc.size(); ++i)  // lens-hidden pixels are never scored
        w[i] = ecc[i] <= radius_deg && !lens.hidden(int(i % std::size_t(view.width())), int(i / std::size_t(view.width())))
                   ? 1.0f
                   : 0.0f;
      const double ppd = std::sqrt(view.pixels_per_deg2(*truth));
      const core::Scores sc = core::pool(core::error_maps(pipe.image(core::Eye::Left), reference, ppd), w);
      if (sc.weight <= 0) continue;  // the true gaze is off the view
      q.psnr += sc.psnr;
      q.hdr_flip += sc.hdr_flip;
      q.ldr_flip += sc.ldr_flip;
      ++q.frames;
    }
  }
  if (q.frames) q.psnr /= q.frames, q.hdr_flip /= q.frames, q.ldr_flip /= q.frames;
  return q;
}

// The gaze source options with a compensation mode: the delivered samples predicted to the
// display time, at most the default horizon ahead (Landing: a trusted fit, uncapped).
devices::SourceOptions predicting(devices::SourceOptions o, devices::PredictMode m) {
  o.predict = m;
  o.horizon_ns = m == devices::PredictMode::None ? 0 : devices::SourceOptions{}.horizon_ns;
  return o;
}

int run(std::vector<std::string> argv) {
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") {
      std::cout << kHelpHead << frame_options_help({"jitter"}) << kHelpTail;
      return 0;
    }
  const std::vector<std::string> sim_options{"scene", "display", "gaze", "tracker", "tracker-delay", "jitter", "rate",
                                             "predict", "seconds", "render-time", "scan-out", "persistence",
                                             "inject-latency", "quality-frames", "reference-spp", "budget", "cap",
                                             "quality-at", "quality-radius", "reference-error", "reference-cache",
                                             "distribution", "denoiser", "bmfr-precision", "stereo-share", "trace",
                                             "bounces", "seed", "landing-spp", "pixel-albedo",
                                             "lattice-blur", "raster-filter"};
  std::vector<std::string> valued = sim_options;
  valued.insert(valued.end(), {"records", "out"});
  const Args args(argv, valued, {"quiet", "no-main-render"});
  const fs::path out(args.str("out", "out/latency"));
  if (args.has("records")) {
    for (const auto& o : sim_options)
      if (args.has(o)) throw core::InputError("--" + o + " configures a simulation; --records analyses a file");
    core::prepare_output_dir(out.string(), "--out");
    return run_records(args, out);
  }

  const core::DisplayPreset display = core::load_display(args.str("display", core::kDefaultDisplay));
  const double seconds = args.num("seconds", 2);
  if (!(seconds > 0 && seconds <= 600)) throw core::InputError("--seconds must be in (0, 600]");
  const std::string predict = args.str("predict", "none");
  devices::PredictMode predict_mode;
  try {
    predict_mode = devices::parse_predict_mode(predict);
  } catch (const core::InputError& e) {
    throw core::InputError(std::string("--predict: ") + e.what());
  }
  latency::TrackerChoice tracker;
  tracker.preset = args.str("tracker", "fove0");
  if (auto t = args.opt("tracker-delay")) tracker.delay_ns = core::parse_duration_ns(*t, "--tracker-delay");
  if (auto t = args.opt("jitter")) tracker.jitter_ns = core::parse_duration_ns(*t, "--jitter");
  if (args.has("rate")) tracker.rate_hz = args.num("rate", 0);
  std::optional<core::TimeNs> fixed_cost;
  if (auto t = args.opt("render-time")) fixed_cost = core::parse_duration_ns(*t, "--render-time");
  const bool main_render = !args.has("no-main-render");
  if (!main_render && !fixed_cost) throw core::InputError("--no-main-render needs --render-time: the cost of a frame not rendered is unknown");
  latency::Scenario sc;
  sc.display.refresh_hz = display.refresh_hz;
  sc.display.scan_out = xrcommon::parse_scan_out(args.str("scan-out", "global"));
  if (auto t = args.opt("persistence")) sc.display.persistence_ns = core::parse_duration_ns(*t, "--persistence");
  sc.display.validate();
  sc.duration_ns = core::TimeNs(std::llround(seconds * 1e9));
  const std::vector<core::TimeNs> injected = parse_latency_list(args.str("inject-latency", "0,25,50,75,100"));
  const long quality_frames = args.integer("quality-frames", 8);
  if (quality_frames < 0 || quality_frames > 1000) throw core::InputError("--quality-frames must be in 0..1000");
  const long ref_spp = args.integer("reference-spp", 64);
  if (ref_spp < 1 || ref_spp > 65536) throw core::InputError("--reference-spp must be in 1..65536");
  const double ref_error = args.num("reference-error", 0.02);
  if (!(ref_error >= 0) || !std::isfinite(ref_error)) throw core::InputError("--reference-error must be >= 0");
  const auto cache_opt = args.opt("reference-cache");
  const std::string ref_cache = reference_cache_arg(cache_opt ? &*cache_opt : nullptr);
  const double radius = args.num("quality-radius", 2.5);
  if (!(radius > 0 && radius <= 90)) throw core::InputError("--quality-radius must be in (0, 90] degrees");
  // The points whose quality is rendered: each costs its frames again on the device.
  std::vector<core::TimeNs> quality_at = injected;
  if (const auto q = args.opt("quality-at"); q && *q != "all") {
    quality_at = parse_latency_list(*q);
    for (core::TimeNs t : quality_at)
      if (std::find(injected.begin(), injected.end(), t) == injected.end())
        throw core::InputError("--quality-at: " + std::to_string(core::ns_to_ms(t)) + " ms is not in --inject-latency");
  }
  // The frame of `fovea render`: the same defaults and option names (pipeline/frame_config.hpp).
  const pipeline::FrameConfig frame = frame_config_of(args, {"jitter"});
  sc.hold_deg = core::GridHold::radius_for_margin(frame.distribution.margin_deg);
  const std::string gaze_uri = args.str("gaze", kDefaultGaze);
  devices::SourceOptions so;
  so.display = display;
  so = predicting(so, predict_mode);
  std::unique_ptr<devices::TrackerModel> model = latency::open_tracker(gaze_uri, tracker, so);
  const bool quiet = args.has("quiet");

  const renderer::Scene scene = renderer::load_scene(args.str("scene", "default"));
  for (const auto& w : scene.warnings) std::cerr << "warning: " << w << "\n";
  core::prepare_output_dir(out.string(), "--out");
  // The defaults of `fovea render`: distribution, reconstruction, tracing, the hidden area culled.
  RenderSetup setup(scene, display, frame);
  gpu::Context& ctx = setup.ctx;
  pipeline::FrameDriver& driver = setup.driver;
  pipeline::FramePipeline& pipe = driver.pipeline();

  // The main run: every frame rendered; its cost is the measured CPU time of the frame (the
  // submission waits for the GPU, so the GPU's work is inside it) or the fixed one.
  std::vector<core::TimeNs> measured;  // the cost each frame was given
  std::vector<double> pipeline_ms;     // what each frame took here
  const latency::RenderFn render = [&](std::int64_t f, const devices::FoveaGaze& gaze) {
    latency::FrameWork w;
    if (!main_render) {
      w.cost_ns = *fixed_cost;
      measured.push_back(w.cost_ns);
      return w;
    }
    // The simulation read the gaze (modelled as instant on its timeline).
    const pipeline::DrivenFrame d = driver.step(std::uint32_t(f), gaze, driver.static_poses());
    w.cost_ns = fixed_cost ? *fixed_cost : core::ms_to_ns(d.times.cpu_ms());
    measured.push_back(w.cost_ns);
    pipeline_ms.push_back(d.times.cpu_ms());
    w.cpu_ms = d.cpu_ms();
    w.gpu_ms = d.gpu_ms();
    if (!quiet) std::fprintf(stderr, "\rframe %lld", static_cast<long long>(f + 1));
    return w;
  };
  const latency::Simulation sim = latency::simulate(*model, sc, render);
  if (!quiet) std::fprintf(stderr, "\n");
  xrcommon::TimingWriter writer;
  writer.open((out / "records.jsonl").string(), xrcommon::TimingWriter::Mode::Atomic);
  for (const auto& r : sim.records)
    if (!writer.write(r)) throw std::runtime_error(writer.error());
  writer.close();

  std::vector<double> cost_ms;
  for (core::TimeNs c : measured) cost_ms.push_back(core::ns_to_ms(c));
  const latency::Distribution cost = latency::distribution(cost_ms);
  const latency::Distribution took = latency::distribution(pipeline_ms);
  const std::string cost_text = fixed_cost ? "fixed --render-time " + std::to_string(core::ns_to_ms(*fixed_cost)) + " ms"
                                           : "measured CPU time per frame (GPU wait included)";
  nlohmann::json j = latency::summarize(sim.records, &sim);
  j["mode"] = "simulation";
  j["clock"] = "virtual";
  j["render_cost"] = {{"source", fixed_cost ? "fixed" : "measured"},
                      {"ms", latency::to_json(cost)},
                      {"measured_ms", latency::to_json(took)},
                      {"main_run_rendered", main_render},
                      {"note", cost_text}};
  const devices::TrackerParams& tp = model->params();
  j["config"] = {{"scene", args.str("scene", "default")},
                 {"display", display.name},
                 {"refresh_hz", display.refresh_hz},
                 {"scan_out", xrcommon::scan_out_name(sc.display.scan_out)},
                 {"persistence_ms", core::ns_to_ms(sc.display.persistence_ns)},
                 {"compositor_budget_ms", core::ns_to_ms(xrcommon::DisplayModel(sc.display).compositor_budget())},
                 {"gaze", gaze_uri},
                 {"tracker", {{"preset", tp.name}, {"rate_hz", tp.rate_hz}, {"delay_ms", core::ns_to_ms(tp.delay_ns)},
                              {"jitter_ms", core::ns_to_ms(tp.jitter_ns)}, {"noise_deg", tp.noise_deg},
                              {"dropout", tp.dropout}}},
                 {"predict", predict},
                 {"budget", frame.distribution.budget},
                 {"frame_options", to_json(frame)},
                 {"seconds", seconds},
                 {"device", {{"name", ctx.info().name}, {"driver", ctx.info().driver}}}};
  char notebuf[256];
  std::snprintf(notebuf, sizeof notebuf, "%s %.0f Hz, budget %.2f, tracker %s %.0f Hz delay %.1f ms jitter %.1f ms, render %s",
                display.name.c_str(), display.refresh_hz, frame.distribution.budget, tp.name.c_str(), tp.rate_hz,
                core::ns_to_ms(tp.delay_ns), core::ns_to_ms(tp.jitter_ns), fixed_cost ? "fixed" : "measured");
  std::vector<sweep::Chart> charts = latency::plots(sim.records, &sim, notebuf);

  // The comparisons replay the main run's costs frame by frame, so every run has the same
  // frames at the same times and differs only by the gaze the frames were foveated for.
  const latency::RenderFn replay = [&](std::int64_t f, const devices::FoveaGaze&) {
    latency::FrameWork w;
    w.cost_ns = measured.empty() ? 0 : measured[std::min<std::size_t>(std::size_t(f), measured.size() - 1)];
    return w;
  };
  // Compensation, measured: the foveal error after saccades with and without prediction.
  nlohmann::json compensation = nlohmann::json::array();
  for (devices::PredictMode m : {devices::PredictMode::None, devices::PredictMode::Linear, devices::PredictMode::Landing}) {
    std::unique_ptr<devices::TrackerModel> t = latency::open_tracker(gaze_uri, tracker, predicting(so, m));
    const latency::Simulation s = latency::simulate(*t, sc, replay);
    compensation.push_back({{"predict", devices::predict_mode_name(m)},
                            {"post_saccade_error_deg", latency::error_summary(latency::post_saccade_errors(s))},
                            {"foveal_error_deg", latency::error_summary(latency::shown_errors(s))},
                            {"recovery_ms", latency::to_json(latency::distribution(latency::recovery_ms(s)))}});
  }
  j["compensation"] = compensation;

  if (!injected.empty()) {
    std::optional<core::Image> reference;
    const std::size_t warm = 3;
    if (quality_frames > 0 && !quality_at.empty()) {
      ReferenceRequest req;
      req.scene = args.str("scene", "default");
      // The render's own light transport, as `fovea render --reference` (one cache).
      req.settings = reference_settings(scene, pipeline::path_config(frame.bounces, scene));
      req.settings.max_spp = std::uint32_t(ref_spp);
      req.settings.until_pixel_rel_error = ref_error;
      req.cache_dir = ref_cache;
      if (!quiet) std::fprintf(stderr, "reference, up to %ld spp...\n", ref_spp);
      CachedReference ref = cached_reference(ctx, setup.driver.gpu_scene(), pipe.view(core::Eye::Left), core::Eye::Left, req);
      j["quality_reference"] = {{"transport", pipeline::transport_json(pipeline::path_config(frame.bounces, scene),
                                                                        "the render's")},
                                {"spp", ref.result.spp},
                                {"pixel_rel_error", ref.result.pixel_rel_error},
                                {"key", ref.key},
                                {"from_cache", ref.from_cache}};
      reference = std::move(ref.result.image);
    }
    std::vector<latency::SweepPoint> points;
    nlohmann::json sweep = nlohmann::json::array();
    for (core::TimeNs inj : injected) {
      latency::TrackerChoice c = tracker;
      c.inject_ns = inj;
      std::unique_ptr<devices::TrackerModel> m = latency::open_tracker(gaze_uri, c, so);
      const latency::Simulation s = latency::simulate(*m, sc, replay);
      latency::SweepPoint p;
      p.inject_ms = core::ns_to_ms(inj);
      p.error = latency::error_summary(latency::shown_errors(s));
      const latency::Distribution g2p = latency::distribution(latency::latencies(s.records).gaze_to_photon_ms);
      const std::vector<double> rec = latency::recovery_ms(s);
      const latency::Distribution recovery = latency::distribution(rec);
      p.gaze_to_photon_median_ms = g2p.median;
      p.recovery_median_ms = recovery.median;
      p.recovered = rec.size();
      // Medians of no values are null (to_json), as in every summary.
      nlohmann::json pj = {{"inject_ms", p.inject_ms},
                           {"gaze_to_photon_median_ms", latency::to_json(g2p)["median"]},
                           {"foveal_error_deg", p.error},
                           {"recovery_ms_median", latency::to_json(recovery)["median"]},
                           {"saccades_recovered", p.recovered}};
      if (reference && std::find(quality_at.begin(), quality_at.end(), inj) != quality_at.end()) {
        if (!quiet) std::fprintf(stderr, "quality at +%.0f ms...\n", p.inject_ms);
        const Quality q = fovea_quality(pipe, driver.static_poses(), s, std::size_t(quality_frames), warm, radius, *reference,
                                        core::EyeOptics(display, core::Eye::Left).view_mask());
        if (q.frames) {
          p.fovea_psnr_db = q.psnr;
          p.fovea_hdr_flip = q.hdr_flip;
          p.quality_radius_deg = radius;
          p.quality_frames = std::size_t(q.frames);
          p.quality_saccades = std::size_t(q.saccades);
          pj["fovea_quality"] = {{"psnr_db", q.psnr},      {"hdr_flip", q.hdr_flip}, {"ldr_flip", q.ldr_flip},
                                 {"radius_deg", radius}, {"frames", q.frames},     {"saccades", q.saccades}};
        }
      }
      points.push_back(p);
      sweep.push_back(pj);
    }
    j["sweep"] = sweep;
    for (auto& c : latency::sweep_plots(points, notebuf)) charts.push_back(std::move(c));
  }
  finish(out, j, sweep::write_charts(out.string(), "figures.json", charts));
  return 0;
}

}  // namespace

FOVEA_COMMAND(latency_command, "latency", "latency harness: tracker + pipeline + display model, gaze-to-photon, foveal error",
              run);

}  // namespace fovea::tools::cmd_latency
