// fovea render: foveated stereo path tracing with reconstruction in grid space, per-frame
// PNGs, an EXR of the last frame and report.json with timings and quality.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <optional>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fovea/core/acuity.hpp"
#include "fovea/core/clock.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/flip.hpp"
#include "fovea/core/json.hpp"
#include "fovea/core/metrics.hpp"
#include "fovea/core/output_path.hpp"
#include "fovea/devices/foveation_gaze.hpp"
#include "fovea/devices/readers.hpp"
#include "fovea/devices/screen.hpp"
#include "frame_log.hpp"
#include "reference_cache.hpp"
#include "render_setup.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/reconstruct/bmfr.hpp"
#include "fovea/renderer/reference.hpp"
#include "fovea/renderer/scene_io.hpp"

namespace fovea::tools::cmd_render {
namespace {

namespace fs = std::filesystem;

constexpr const char* kHelpHead = R"(usage: fovea render [options]

Renders a stereo sequence: per frame and eye the sample grid follows the gaze, the grid is
path traced (1 sample per cell), reconstructed in grid space (temporal accumulation,
optional stereo sharing of indirect diffuse, BMFR, TAA) and resolved to the display with
the peripheral blur. Writes to --out:
  frame_NNNN_left.png, frame_NNNN_right.png, frame_NNNN_sbs.png   tone-mapped (ACES fit, docs/metrics.md)
  last_left.exr, last_right.exr                                    linear, last frame
  frames.jsonl  per frame: the gaze sample used (its times, flags), the gaze each eye used,
                eye poses, grid size — deterministic: identical runs write identical bytes;
                compare two runs with `fovea replay-diff A B`
  frame_times.jsonl  per frame a timing record (docs/openxr.md): the gaze sample's times, GPU
                and CPU ms per stage
  report.json   {"frames", "samples_traced_per_eye", "samples_hidden": {"left", "right"},
                 "device": {name, driver}, "trace": "rayquery" or "compute",
                 "device_memory": {"heaps": per memory heap its size and what the frames'
                 buffers and images held at the end (held) and at most (peak), MiB;
                 device_local_held_mib, device_local_peak_mib: over the device-local heaps},
                 "gpu_ms": {grid, trace, reconstruct, resolve, total, pixel_albedo (part of trace),
                            accumulate, bmfr_fit, post, mip, resample, blur},
                 "cpu_ms": {gaze, grid, trace, reconstruct, resolve, submit, wait, total}
                 (medians per frame; submit: vkQueueSubmit, wait: the fence; total: the
                 frame alone, without output),
                 "output": {frames_read_back, host_bytes_read_back, host_bytes_per_frame,
                 readback_cpu_ms, write_cpu_ms}: images are read back only for the frames
                 written (--png-every), the flicker window (the last 8) and
                 the recovery curve's (left eye),
                 "metrics": {tone mapper, exposure, ppd, reference},
                 "recovery": the saccade recovery curve (--recovery-frames),
                 "summary": {"left": {...}, "right": {...}}}
Cells that the preset's lens hides (its hidden area, seen from the view) are neither traced
nor reconstructed; samples_hidden counts them in the last frame.
With --reference each eye's summary compares the last frame with a converged Cartesian
reference (docs/metrics.md): tone-mapped PSNR and SSIM (ACES fit + sRGB), relMSE (linear),
LDR- and HDR-FLIP, each over the whole image, the fovea (fovea_*, e <= 5.79 deg),
acuity-weighted (foveated_*) and per 2 deg band ("bands"). Always: temporal_error, and the
flicker of the still image over the trailing frames whose gaze did not move (up to 8); when
the gaze moved between the last two frames there is nothing still to measure: flicker is
null and flicker_note says so.
With no options: a short demo on the shipped scene and gaze.

  --scene S             cornell | furnace | glossy-spheres | stereo-occluders | default,
                        or a .gltf/.glb/.obj file [default]
  --display NAME|FILE   display preset (fove0, vive, modern, wide, small, tiny) or JSON [small]
  --gaze URI            recording, or synthetic:<seed>[?...] (docs/gaze.md)
                        [the shipped recording data/gaze/default.csv]
  --screen GEOMETRY     what 2-D gaze coordinates refer to: WxH@HFOVxVFOV or
                        WxH@SWxSHmm@Dmm (as the URI key screen=; docs/gaze.md)
  --frames N            frames to render [24]
)";
constexpr const char* kHelpTail = R"(  --no-blur             skip the peripheral blur
  --no-cull             trace the lens' hidden area too
  --reference SPP|DIR   SPP: converged reference of the last frame with the render's own light
                        transport (--bounces; at most SPP samples per pixel, see
                        --reference-error), from the cache or rendered into it: the
                        reference of `fovea reference --spp SPP --until-pixel-rel-error X
                        --bounces N --rr-start 1000` (auto: its defaults), the same cache
                        entry; DIR: load reference_left.exr and reference_right.exr written
                        by `fovea reference` (checked to show this scene and view; a
                        different transport is scored, with a warning and
                        transport.matched false). Lens-hidden pixels are never scored
  --full-gi-score       with --reference SPP: also score against full global illumination
                        (bounces and Russian roulette from the scene's albedo), as
                        summary.*.full_gi (the same object when --bounces auto)
  --reference-error X   stop the reference once its per-pixel relative standard error
                        (RMS over the pixels, over the mean luminance) is <= X; 0: off [0.02]
  --reference-window DEG  with --reference SPP: each eye's reference traces only the pixels
                        within DEG degrees of that eye's gaze in the last frame (the scored
                        one; `fovea reference --window X,Y,Z@DEG`, the same cache entry)
                        [the whole view]. A reference that holds a window (this, or a DIR
                        written with --window) scores only the bands, and the fovea, whose
                        pixels and SSIM/FLIP neighbourhoods it holds; the others, the whole
                        image and foveated_* are null, with a note in quality_notes
  --reference-cache DIR|off  where references are cached [$XDG_CACHE_HOME/fovea/references]
  --recovery-frames N   the saccade recovery curve (report.json: recovery): after each
                        saccade of the gaze (a run of frames moving it > 1 deg each, >= 5 deg
                        in all), the left eye's fovea HDR-FLIP and PSNR against the
                        reference on the N frames from the first at the new gaze on (those
                        frames are read back); 0: off [8 with --reference, without
                        --reference-window; else 0]
  --png-every N         write PNGs of every N-th frame (0: last frame only) [1]
  --no-marker           do not mark the gaze in the PNGs
  --out DIR             output directory [out/render]
  --quiet               no progress bar
  --help                this text

Exit status: 0 on success, 2 on invalid arguments or input files, 1 on other errors.
)";

// The shipped gaze recording: next to the sources ($FOVEA_SOURCE_DIR) or above the binary.
std::optional<std::string> shipped_gaze() {
  const fs::path rel = fs::path("data") / "gaze" / "default.csv";
  if (const char* src = std::getenv("FOVEA_SOURCE_DIR"))
    if (fs::exists(fs::path(src) / rel)) return (fs::path(src) / rel).string();
  std::error_code ec;
  fs::path dir = fs::read_symlink("/proc/self/exe", ec).parent_path();
  for (int up = 0; !ec && up < 6 && !dir.empty(); ++up, dir = dir.parent_path())
    if (fs::exists(dir / rel)) return (dir / rel).string();
  if (fs::exists(rel)) return rel.string();
  return std::nullopt;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// A small ring around the gaze point (the marker), drawn into a tone-mapped image.
void mark_gaze(core::Image& img, glm::dvec2 px) {
  const double r = std::max(3.0, img.width / 80.0);
  for (int y = int(px.y - r - 2); y <= int(px.y + r + 2); ++y)
    for (int x = int(px.x - r - 2); x <= int(px.x + r + 2); ++x) {
      if (x < 0 || y < 0 || x >= img.width || y >= img.height) continue;
      const double d = std::hypot(x + 0.5 - px.x, y + 0.5 - px.y);
      if (std::abs(d - r) < 0.8) img.at(x, y) = {0.1f, 1.0f, 0.2f, 1.0f};
    }
}

core::Image side_by_side(const core::Image& a, const core::Image& b) {
  core::Image out(a.width + b.width, std::max(a.height, b.height));
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) out.at(x, y) = a.at(x, y);
  for (int y = 0; y < b.height; ++y)
    for (int x = 0; x < b.width; ++x) out.at(a.width + x, y) = b.at(x, y);
  return out;
}

void progress(int done, int total, double seconds) {
  const int width = 30, fill = width * done / std::max(total, 1);
  std::fprintf(stderr, "\r[%s%s] frame %d/%d  %.1f s", std::string(std::size_t(fill), '#').c_str(),
               std::string(std::size_t(width - fill), ' ').c_str(), done, total, seconds);
  std::fflush(stderr);
}

constexpr double kExposure = 0.0;  // of the display transform every metric uses
constexpr double kBandDeg = 2.0;
constexpr std::size_t kFlickerFrames = 8;

nlohmann::json scores_json(const core::Scores& sc, const std::string& prefix) {
  return {{prefix + "psnr", sc.psnr},
          {prefix + "ssim", sc.ssim},
          {prefix + "rel_mse", sc.rel_mse},
          {prefix + "ldr_flip", sc.ldr_flip},
          {prefix + "hdr_flip", sc.hdr_flip}};
}

// The eccentricity of a lens-hidden pixel: no weight anywhere (fovea, acuity, bands, whole).
constexpr float kHidden = std::numeric_limits<float>::quiet_NaN();

// 1 for the pixels that are scored (finite eccentricity), 0 for the hidden ones.
std::vector<float> visible_weights(const std::vector<float>& ecc) {
  std::vector<float> w(ecc.size());
  for (std::size_t i = 0; i < ecc.size(); ++i) w[i] = std::isfinite(ecc[i]) ? 1.0f : 0.0f;
  return w;
}

std::vector<float> fovea_weights(const std::vector<float>& ecc) {
  std::vector<float> w(ecc.size());
  for (std::size_t i = 0; i < ecc.size(); ++i) w[i] = ecc[i] <= core::acuity::kFoveaDeg ? 1.0f : 0.0f;
  return w;
}

nlohmann::json missing_scores(const std::string& prefix) {
  nlohmann::json j;
  for (const char* k : {"psnr", "ssim", "rel_mse", "ldr_flip", "hdr_flip"}) j[prefix + k] = nullptr;
  return j;
}

// Quality of `img` against `ref`: whole image, fovea, acuity-weighted and per band. A
// reference that holds only a window (`valid`, one flag per pixel; empty: every pixel)
// scores a region only when it holds every pixel the region's error maps read (the region
// and error_map_support_px around it), so those scores are the ones a whole reference with
// the same pixels gives; the other regions are null, never scored against the untraced
// zeros, with a note in quality_notes.
// Each pixel's eccentricity from `gaze`, kHidden where the display's lens hides it: nobody
// sees those pixels, so no score counts them.
std::vector<float> scored_eccentricity(const core::View& v, glm::dvec3 gaze, const core::ViewMask& lens) {
  std::vector<float> ecc = core::eccentricity_map(v, gaze);
  for (int y = 0; y < v.height(); ++y)
    for (int x = 0; x < v.width(); ++x)
      if (lens.hidden(x, y)) ecc[std::size_t(y) * std::size_t(v.width()) + std::size_t(x)] = kHidden;
  return ecc;
}

// The error maps of `rendered` against `ref`, its lens-hidden pixels (kHidden eccentricity)
// given the reference's values: they score 0 and their neighbours' SSIM and FLIP windows do
// not see the black lens edge.
core::ErrorMaps scored_maps(const core::Image& rendered, const core::Image& ref, const std::vector<float>& ecc, double ppd,
                            const std::vector<bool>& valid = {}) {
  core::Image img = rendered;
  for (std::size_t i = 0; i < ecc.size(); ++i)
    if (std::isnan(ecc[i])) img.pixels[i] = ref.pixels[i];
  return core::error_maps(img, ref, ppd, kExposure, valid);
}

void add_quality(nlohmann::json& s, const core::Image& img, const core::Image& ref, const std::vector<bool>& valid,
                 const std::vector<float>& ecc, double ppd) {
  const std::vector<float> visible = visible_weights(ecc);
  const core::ErrorMaps maps = scored_maps(img, ref, ecc, ppd, valid);
  // What a missing pixel takes away: the whole image and the acuity weights (nowhere 0)
  // always, the fovea and the bands where it falls.
  bool whole = true, fovea = true;
  std::vector<bool> band_ok;
  const int support = core::error_map_support_px(ppd);
  if (!valid.empty()) {
    const std::vector<bool> scorable = core::scorable_pixels(valid, img.width, img.height, support);
    for (std::size_t i = 0; i < scorable.size(); ++i) {
      if (scorable[i] || !std::isfinite(ecc[i])) continue;
      whole = false;
      if (ecc[i] <= core::acuity::kFoveaDeg) fovea = false;
      const int k = core::band_index(ecc[i], kBandDeg);
      if (band_ok.size() <= std::size_t(k)) band_ok.resize(std::size_t(k) + 1, true);
      band_ok[std::size_t(k)] = false;
    }
  }
  nlohmann::json notes = nlohmann::json::array();
  const std::size_t held = valid.empty() ? valid.size() : std::size_t(std::count(valid.begin(), valid.end(), true));
  char lacks[160];
  std::snprintf(lacks, sizeof lacks, "the reference is a window of %.2f%% of the pixels and lacks", 100.0 * double(held) /
                double(std::max<std::size_t>(valid.size(), 1)));
  const std::string margin = " or within " + std::to_string(support) + " px of them (the SSIM and FLIP neighbourhoods)";
  if (whole) {
    s.update(scores_json(core::pool(maps, visible), ""));
    s.update(scores_json(core::pool(maps, core::foveation_weights(ecc)), "foveated_"));
    std::vector<bool> seen(visible.size());
    for (std::size_t i = 0; i < seen.size(); ++i) seen[i] = visible[i] > 0;
    s["linear_psnr"] = core::psnr_masked(img, ref, seen);  // linear HDR, peak 1: dominated by emitters
  } else {
    s.update(missing_scores(""));
    s.update(missing_scores("foveated_"));
    s["linear_psnr"] = nullptr;
    notes.push_back(std::string("whole-image (psnr, ssim, rel_mse, ldr_flip, hdr_flip, linear_psnr) and acuity-weighted "
                                "(foveated_*) scores not computed: ") + lacks + " pixels they need");
  }
  if (fovea) {
    s.update(scores_json(core::pool(maps, fovea_weights(ecc)), "fovea_"));
  } else {
    s.update(missing_scores("fovea_"));
    notes.push_back(std::string("fovea_* not computed: ") + lacks + " pixels of the fovea" + margin);
  }
  nlohmann::json bands = nlohmann::json::array();
  int missing = 0;
  for (const core::BandScores& b : core::band_scores(maps, ecc, kBandDeg)) {
    nlohmann::json o = {{"e_min", b.e_min}, {"e_max", b.e_max}, {"pixels", b.pixels}};
    const std::size_t k = std::size_t(std::llround(b.e_min / kBandDeg));
    if (k < band_ok.size() && !band_ok[k]) {
      o.update(missing_scores(""));
      o["missing"] = std::string(lacks) + " pixels of this band" + margin;
      ++missing;
    } else {
      o.update(scores_json(b.scores, ""));
    }
    bands.push_back(o);
  }
  s["bands"] = bands;
  if (missing) notes.push_back(std::to_string(missing) + " bands not computed (null, see their \"missing\")");
  if (!notes.empty()) s["quality_notes"] = notes;
}

// Flicker of the still frames: whole image, fovea, acuity-weighted and per band.
void add_flicker(nlohmann::json& s, const std::deque<core::Image>& frames, const std::vector<float>& ecc) {
  const std::vector<float> map = core::flicker_map({frames.begin(), frames.end()}, kExposure);
  s["flicker_frames"] = frames.size();
  s["flicker"] = core::weighted_mean(map, visible_weights(ecc));
  s["fovea_flicker"] = core::weighted_mean(map, fovea_weights(ecc));
  s["foveated_flicker"] = core::weighted_mean(map, core::foveation_weights(ecc));
  float e_max = 0;
  for (float e : ecc) e_max = std::max(e_max, e);
  nlohmann::json bands = nlohmann::json::array();
  for (int k = 0; k * kBandDeg <= e_max; ++k) {
    std::vector<float> w(ecc.size());
    long pixels = 0;
    for (std::size_t i = 0; i < ecc.size(); ++i)
      if (ecc[i] >= k * kBandDeg && ecc[i] < (k + 1) * kBandDeg) w[i] = 1.0f, ++pixels;
    if (pixels > 0)
      bands.push_back({{"e_min", k * kBandDeg}, {"e_max", (k + 1) * kBandDeg}, {"pixels", pixels},
                       {"flicker", core::weighted_mean(map, w)}});
  }
  s["flicker_bands"] = bands;
}

constexpr long kRecoveryFrames = 8;  // 114 ms at 70 Hz: the 50 ms goal and what follows

// The saccade recovery curve (docs/metrics.md): after each saccade of the gaze the grid used
// (the left eye's, one frame moving it by more than kMovingDeg, a run of them by at least
// kSaccadeDeg in all), the fovea's HDR-FLIP and PSNR on the `frames` frames from the one
// that reached the new place (k = 1) on. A saccade that starts before the curve is complete
// ends it early (counted as incomplete, as is one the run ends).
class Recovery {
 public:
  static constexpr double kMovingDeg = 1.0, kSaccadeDeg = 5.0;
  explicit Recovery(long frames) : frames_(frames) {}

  // The gaze of the frame just rendered; true when this frame is on a curve (score it).
  bool track(glm::dvec3 gaze) {
    if (frames_ == 0) return false;
    const double step = has_last_ ? core::angle_deg(last_, gaze) : 0.0;
    last_ = gaze;
    has_last_ = true;
    if (step > kMovingDeg) {
      run_deg_ += step;
      if (run_deg_ >= kSaccadeDeg) {  // (again, while the same saccade goes on)
        if (current_ && !in_flight_ && current_->hdr_flip.size() < std::size_t(frames_)) ++interrupted_;
        current_ = Landing{0, run_deg_, {}, {}};
        in_flight_ = true;
        return true;
      }
    } else {
      run_deg_ = 0;
      in_flight_ = false;
    }
    return current_ && current_->hdr_flip.size() < std::size_t(frames_);
  }

  void add(long frame, double hdr_flip, double psnr) {
    if (current_->hdr_flip.empty()) current_->frame = frame;
    current_->hdr_flip.push_back(hdr_flip);
    current_->psnr.push_back(psnr);
    if (current_->hdr_flip.size() == std::size_t(frames_)) done_.push_back(*current_);
  }

  nlohmann::json to_json() const {
    nlohmann::json landings = nlohmann::json::array();
    std::vector<double> mean(std::size_t(frames_), 0.0);
    for (const Landing& l : done_) {
      landings.push_back({{"frame", l.frame}, {"amplitude_deg", l.amplitude_deg}, {"fovea_hdr_flip", l.hdr_flip},
                          {"fovea_psnr", l.psnr}});
      for (std::size_t k = 0; k < mean.size(); ++k) mean[k] += l.hdr_flip[k] / double(done_.size());
    }
    return {{"frames", frames_},
            {"moving_deg", kMovingDeg},
            {"saccade_deg", kSaccadeDeg},
            {"landings", landings},
            {"incomplete", interrupted_ + (current_ && current_->hdr_flip.size() < std::size_t(frames_) ? 1 : 0)},
            {"mean_fovea_hdr_flip", done_.empty() ? nlohmann::json() : nlohmann::json(mean)},
            {"note", "left eye; k = 1 is the first frame whose grid reached the new gaze; compare with the summary's "
                     "fovea_hdr_flip of a still gaze (docs/metrics.md, \"Saccade recovery\")"}};
  }

 private:
  struct Landing {
    long frame = 0;
    double amplitude_deg = 0;
    std::vector<double> hdr_flip, psnr;
  };
  long frames_;
  glm::dvec3 last_{0, 0, -1};
  bool has_last_ = false;
  double run_deg_ = 0;
  bool in_flight_ = false;  // current_ began in the saccade still moving the gaze
  std::optional<Landing> current_;
  std::vector<Landing> done_;
  long interrupted_ = 0;
};

int run(std::vector<std::string> argv) {
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") {
      std::cout << kHelpHead << frame_options_help() << kHelpTail;
      return 0;
    }
  const Args args(argv,
                  {"scene", "display", "gaze", "frames", "distribution", "budget", "cap", "jitter", "denoiser", "bmfr-precision",
                   "stereo-share", "bounces", "reference", "reference-error", "reference-cache", "reference-window", "recovery-frames", "png-every",
                   "out", "screen", "trace", "seed", "landing-spp", "pixel-albedo",
                   "lattice-blur", "raster-filter"},
                  {"no-blur", "no-cull", "no-marker", "quiet", "full-gi-score"});
  const long frames = args.integer("frames", 24);
  if (frames < 1 || frames > 100000) throw core::InputError("--frames must be in 1..100000");
  // --reference: a sample count renders (or finds in the cache), anything else is a directory.
  const std::string ref_arg = args.str("reference", "0");
  const bool ref_is_spp = !ref_arg.empty() && ref_arg.find_first_not_of("0123456789") == std::string::npos;
  const long ref_spp = ref_is_spp ? args.integer("reference", 0) : 0;
  if (ref_spp < 0 || ref_spp > (1L << 20)) throw core::InputError("--reference must be in 1..1048576 samples per pixel");
  const std::string ref_dir = ref_is_spp ? "" : ref_arg;
  if (!ref_dir.empty() && !fs::is_directory(ref_dir))
    throw core::InputError("--reference: \"" + ref_dir + "\" is neither a sample count nor a directory");
  const double ref_error = args.num("reference-error", kDefaultPixelRelError);
  if (!(ref_error >= 0) || !std::isfinite(ref_error)) throw core::InputError("--reference-error must be >= 0");
  const auto cache_opt = args.opt("reference-cache");
  const std::string ref_cache = reference_cache_arg(cache_opt ? &*cache_opt : nullptr);
  if (args.has("reference-window") && ref_spp == 0)
    throw core::InputError("--reference-window: only with --reference SPP (a DIR reference brings its own window)");
  const bool ref_window = args.has("reference-window");
  const double ref_window_deg = args.num("reference-window", 0);
  const long png_every = args.integer("png-every", 1);
  if (png_every < 0) throw core::InputError("--png-every must be >= 0");
  const core::DisplayPreset display = core::load_display(args.str("display", core::kDefaultDisplay));
  pipeline::FrameConfig frame_config = frame_config_of(args);
  core::DistributionParams& dp = frame_config.distribution;
  reconstruct::ReconSettings& settings = frame_config.recon;
  settings.blur = !args.has("no-blur");
  const fs::path out_dir(args.str("out", "out/render"));
  core::prepare_output_dir(out_dir.string(), "--out");

  std::string gaze_uri;
  if (auto g = args.opt("gaze")) {
    gaze_uri = *g;
  } else if (auto shipped = shipped_gaze()) {
    gaze_uri = *shipped;
  } else {
    std::cerr << "warning: the shipped gaze recording (data/gaze/default.csv) was not found; using synthetic:7\n";
    gaze_uri = "synthetic:7";
  }
  devices::SourceOptions so;
  so.display = display;
  if (auto sc = args.opt("screen")) so.screen = devices::parse_screen(*sc, "--screen");
  auto gaze_source = std::make_unique<devices::FoveationGaze>(gaze_uri, so);
  for (const auto& n : devices::recording_notes(gaze_uri, so)) std::cerr << "warning: " << n << "\n";

  const std::string scene_arg = args.str("scene", "default");
  const renderer::Scene scene = renderer::load_scene(scene_arg);
  for (const auto& w : scene.warnings) std::cerr << "warning: " << w << "\n";

  const bool cull = !args.has("no-cull");
  RenderSetup setup(scene, display, frame_config, cull);
  gpu::Context& ctx = setup.ctx;
  pipeline::FrameDriver& driver = setup.driver;
  driver.set_gaze(std::move(gaze_source));
  const renderer::GpuScene& gpu_scene = driver.gpu_scene();
  pipeline::FramePipeline& pipeline = driver.pipeline();
  // Each eye's lens mask: the pixels no score counts (built once, used per scored frame).
  const std::array<core::ViewMask, 2> lens{core::EyeOptics(display, core::Eye::Left).view_mask(),
                                           core::EyeOptics(display, core::Eye::Right).view_mask()};

  // The same settings as `fovea reference --spp SPP --until-pixel-rel-error X`: one cache.
  // The scores compare against the render's own transport; full GI (the albedo rule) is a
  // score of its own (--full-gi-score).
  const auto request_for = [&](ReferenceSettings s) {
    s.max_spp = std::uint32_t(ref_spp);
    s.until_pixel_rel_error = ref_error;
    return ReferenceRequest{scene_arg, s, {}, ref_cache};
  };
  const renderer::PathConfig transport = pipeline::path_config(frame_config.bounces, scene);
  const ReferenceRequest full_gi_request = request_for(reference_defaults(scene));
  const ReferenceRequest ref_request = request_for(reference_settings(scene, transport));
  const bool full_gi_is_matched = ref_request.settings.bounces == full_gi_request.settings.bounces &&
                                  ref_request.settings.rr_start == full_gi_request.settings.rr_start;
  const bool full_gi_score = args.has("full-gi-score");
  if (full_gi_score && ref_spp == 0) throw core::InputError("--full-gi-score: only with --reference SPP");
  // A loaded reference and the window's radius are checked before the frames are paid for
  // (the gaze is inside the view: a disc at its centre stands for it).
  if (ref_window)
    renderer::window_coverage({{{pipeline.view(core::Eye::Left).centre_dir(), ref_window_deg}}},
                              pipeline.view(core::Eye::Left), "--reference-window");
  std::array<std::optional<CachedReference>, 2> loaded;
  if (!ref_dir.empty())
    for (int e = 0; e < 2; ++e) {
      const std::string file = (fs::path(ref_dir) / (std::string("reference_") + (e ? "right" : "left") + ".exr")).string();
      loaded[e] = read_reference(file, scene_arg, pipeline.view(core::Eye(e)), core::Eye(e));
    }
  const bool bar = !args.has("quiet") && stderr_is_tty();
  const bool marker = !args.has("no-marker");
  // The saccade recovery curve scores the left eye's fovea on the frames after each landing,
  // during the run: its reference is needed first (the view is static: the one the summary
  // uses too). A window reference holds one gaze's surroundings only.
  const bool scored = ref_spp > 0 || !ref_dir.empty();
  const long recovery_frames = args.integer("recovery-frames", scored && !ref_window ? kRecoveryFrames : 0);
  if (recovery_frames < 0 || recovery_frames > 1000) throw core::InputError("--recovery-frames must be in 0..1000");
  if (recovery_frames > 0 && (!scored || ref_window))
    throw core::InputError("--recovery-frames: needs --reference SPP or DIR, without --reference-window");
  if (recovery_frames > 0 && !loaded[0]) {
    if (bar) std::fprintf(stderr, "reference left eye, up to %ld spp...\n", ref_spp);
    loaded[0] = cached_reference(ctx, gpu_scene, pipeline.view(core::Eye::Left), core::Eye::Left, ref_request);
    write_reference((out_dir / "reference_left.exr").string(), *loaded[0]);
  }
  Recovery recovery(recovery_frames);
  ctx.reset_memory_peaks();  // report.json's device_memory: the frames' own
  // Per-frame times, milliseconds: GPU and CPU per stage (medians reported).
  std::map<std::string, std::vector<double>> gpu_ms, cpu_ms;
  // Output work, apart from the frame: reading images back (only those written or in the
  // flicker window) and encoding and writing them.
  std::vector<double> readback_ms, write_ms, temporal_gpu_ms;
  std::int64_t host_bytes = 0;
  std::array<core::Image, 2> last;
  // The temporal error is measured on the device: no frame is read back for it.
  pipeline.enable_temporal_error();
  // The trailing frames whose gaze equals the last one's: with the head and scene still,
  // every change between them is an artefact (flicker).
  std::array<std::deque<core::Image>, 2> still;
  std::array<glm::dvec3, 2> still_gaze{};
  std::array<glm::dvec3, 2> gaze{glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)};
  // Frames whose gaze the grid could not use as given (core::GazeStatus), per eye.
  std::array<long, 2> gaze_fallback_frames{0, 0}, gaze_clamped_frames{0, 0};
  FrameLog frame_log((out_dir / "frames.jsonl").string(), (out_dir / "frame_times.jsonl").string());
  const core::TimeNs start = core::now_ns();
  for (long f = 0; f < frames; ++f) {
    const pipeline::DrivenFrame step = driver.step(std::uint32_t(f));
    const pipeline::FrameTimes& t = step.times;
    const devices::FoveaGaze& g = step.gaze;
    for (int e = 0; e < 2; ++e) {
      gaze[e] = g.eye(core::Eye(e)).dir;
      gaze_fallback_frames[e] += t.gaze[e].fallback;
      gaze_clamped_frames[e] += t.gaze[e].clamped;
    }
    const auto& dist = pipeline.distribution(core::Eye::Left);
    FrameRecord rec{f, step.frame_ns, g, {t.gaze[0].used, t.gaze[1].used}, driver.static_poses(), dist.columns(),
                    dist.rows(), step.cpu_ms(), step.gpu_ms(), driver.gaze()->live()};
    for (const auto& [name, v] : rec.gpu_ms) gpu_ms[name].push_back(v);
    for (const auto& [name, v] : rec.cpu_ms) cpu_ms[name].push_back(v);
    temporal_gpu_ms.push_back(t.temporal_gpu_ms);
    const bool write = png_every > 0 ? f % png_every == 0 || f == frames - 1 : f == frames - 1;
    // Flicker is measured over the trailing still frames, at most kFlickerFrames of them.
    const bool flicker_window = f >= frames - long(kFlickerFrames);
    if (write || flicker_window) {
      const core::TimeNs t0 = core::now_ns();
      for (int e = 0; e < 2; ++e) {
        last[e] = pipeline.image(core::Eye(e));
        host_bytes += std::int64_t(last[e].pixels.size() * sizeof(last[e].pixels[0]));
      }
      readback_ms.push_back(core::ns_to_ms(core::now_ns() - t0));
      rec.cpu_ms.emplace_back("output_readback", readback_ms.back());
    }
    if (recovery.track(t.gaze[0].used)) {
      const core::TimeNs r0 = core::now_ns();
      if (!(write || flicker_window)) {
        last[0] = pipeline.image(core::Eye::Left);
        host_bytes += std::int64_t(last[0].pixels.size() * sizeof(last[0].pixels[0]));
      }
      const core::View v = pipeline.view(core::Eye::Left);
      const std::vector<float> ecc = scored_eccentricity(v, t.gaze[0].used, lens[0]);
      const core::Scores sc = core::pool(scored_maps(last[0], loaded[0]->result.image, ecc, core::flip_ppd(v)), fovea_weights(ecc));
      recovery.add(f, sc.hdr_flip, sc.psnr);
      rec.cpu_ms.emplace_back("output_recovery", core::ns_to_ms(core::now_ns() - r0));
    }
    std::array<core::Image, 2> ldr;
    if (flicker_window)
      for (int e = 0; e < 2; ++e) {
        if (still[e].empty() || gaze[e] != still_gaze[e]) still[e].clear();
        still_gaze[e] = gaze[e];
        still[e].push_back(last[e]);
        if (still[e].size() > kFlickerFrames) still[e].pop_front();
      }
    if (write) {
      const core::TimeNs t0 = core::now_ns();
      char name[64];
      for (int e = 0; e < 2; ++e) {
        ldr[e] = renderer::tone_map(last[e]);
        const auto& d = pipeline.distribution(core::Eye(e));
        if (marker)
          if (auto px = d.view().dir_to_pixel(d.gaze())) mark_gaze(ldr[e], *px);
        std::snprintf(name, sizeof(name), "frame_%04ld_%s.png", f, e == 0 ? "left" : "right");
        core::write_png((out_dir / name).string(), ldr[e]);
      }
      std::snprintf(name, sizeof(name), "frame_%04ld_sbs.png", f);
      core::write_png((out_dir / name).string(), side_by_side(ldr[0], ldr[1]));
      write_ms.push_back(core::ns_to_ms(core::now_ns() - t0));
      rec.cpu_ms.emplace_back("output_write", write_ms.back());
    }
    frame_log.add(rec);
    if (bar)
      progress(int(f + 1), int(frames),
               double(core::now_ns() - start) * 1e-9);
  }
  if (bar) std::fprintf(stderr, "\n");
  for (int e = 0; e < 2; ++e) {
    const char* name = e == 0 ? "left" : "right";
    if (gaze_fallback_frames[e] > 0)
      std::cerr << "warning: --gaze " << gaze_uri << ": the " << name << " eye's gaze was unusable (behind the viewer, "
                << "zero or not finite) in " << gaze_fallback_frames[e] << " of " << frames
                << " frames; its last usable gaze, or the view centre, was rendered (frames.jsonl: used_gaze)\n";
    if (gaze_clamped_frames[e] > 0)
      std::cerr << "warning: --gaze " << gaze_uri << ": the " << name << " eye's gaze was outside the view in "
                << gaze_clamped_frames[e] << " of " << frames
                << " frames; it was clamped to the view's border (frames.jsonl: used_gaze)\n";
  }
  frame_log.finish();
  // The device memory of the frames (the scene, the frame pipeline, the read-back buffers):
  // held after the last and at most while they ran, apart from any reference's.
  nlohmann::json heaps = nlohmann::json::array();
  const auto mib = [](VkDeviceSize b) { return std::round(double(b) / (1 << 20) * 10) / 10; };
  VkDeviceSize local_held = 0, local_peak = 0;  // device-local heaps (a GPU's own memory)
  for (const gpu::Context::HeapUse& h : ctx.heap_use()) {
    heaps.push_back({{"heap", h.heap}, {"device_local", h.device_local}, {"size_mib", mib(h.size)},
                     {"held_mib", mib(h.held)}, {"peak_mib", mib(h.peak)}});
    if (h.device_local) local_held += h.held, local_peak += h.peak;
  }
  renderer::write_exr((out_dir / "last_left.exr").string(), last[0]);
  renderer::write_exr((out_dir / "last_right.exr").string(), last[1]);

  nlohmann::json j;
  j["frames"] = frames;
  const std::int64_t traced = (pipeline.traced_cells(core::Eye::Left) + pipeline.traced_cells(core::Eye::Right)) / 2;
  j["samples_traced_per_eye"] = traced;
  j["samples_hidden"] = {{"left", pipeline.hidden_cells(core::Eye::Left)},
                         {"right", pipeline.hidden_cells(core::Eye::Right)}};
  j["display_pixels_per_eye"] = std::int64_t(display.width) * display.height;
  j["config"] = {{"scene", args.str("scene", "default")},
                 {"display", display.name},
                 {"gaze", gaze_uri},
                 {"distribution", core::distribution_name(dp.kind)},
                 {"budget", dp.budget},
                 {"grid", {pipeline.distribution(core::Eye::Left).columns(), pipeline.distribution(core::Eye::Left).rows()}},
                 {"denoiser", reconstruct::denoiser_name(settings.denoiser)},
                 {"bmfr_precision", to_json(frame_config)["bmfr-precision"]},
                 {"stereo_share", reconstruct::stereo_share_name(settings.share)},
                 {"blur", settings.blur},
                 {"cull_hidden_area", cull},
                 {"frame_options", to_json(frame_config)}};
  for (const auto& [name, v] : gpu_ms) j["gpu_ms"][name] = median(v);
  for (const auto& [name, v] : cpu_ms) j["cpu_ms"][name] = median(v);
  // Output apart from the frame: the host bytes read back (0 for a frame neither written nor
  // in the flicker window) and the CPU time of reading and of encoding + writing PNGs.
  const auto median_or_null = [](const std::vector<double>& v) { return v.empty() ? nlohmann::json() : nlohmann::json(median(v)); };
  j["output"] = {{"frames_read_back", readback_ms.size()},
                 {"host_bytes_read_back", host_bytes},
                 {"host_bytes_per_frame", double(host_bytes) / double(frames)},
                 {"readback_cpu_ms", median_or_null(readback_ms)},
                 {"write_cpu_ms", median_or_null(write_ms)},
                 {"temporal_error_gpu_ms", median(temporal_gpu_ms)},
                 {"note", "medians over the frames that did each; the frame's own times are gpu_ms and cpu_ms"}};
  // Which Vulkan driver produced the timings (lavapipe 22.3 and 25 differ ~2x).
  // and how BMFR's fit is scheduled on it (reconstruct::bmfr_schedule, the pipeline's).
  const reconstruct::BmfrSchedule bmfr = reconstruct::bmfr_schedule(ctx.info());
  const bool subgroup = bmfr.reduction == reconstruct::BmfrReduction::Subgroup;
  j["device"] = {{"name", ctx.info().name},
                 {"driver", ctx.info().driver},
                 {"bmfr_fit", {{"workgroup", bmfr.workgroup}, {"reduction", subgroup ? "subgroup" : "serial"}}}};
  j["device_memory"] = {{"heaps", heaps},
                        {"device_local_held_mib", mib(local_held)},
                        {"device_local_peak_mib", mib(local_peak)},
                        {"note", "per memory heap: what this run's buffers and images held after the last frame (held) and "
                                 "at most while the frames ran (peak), MiB; references apart; device_local_*: the sums "
                                 "over the device-local heaps"}};
  j["trace"] = renderer::tracing_name(gpu_scene.tracing());
  const renderer::TraceChoice& choice = setup.driver.trace_choice();
  j["trace_choice"] = {{"requested", args.str("trace", "auto")},
                       {"why", choice.why},
                       {"compute_ms", choice.compute_ms ? nlohmann::json(*choice.compute_ms) : nlohmann::json()},
                       {"rayquery_ms", choice.rayquery_ms ? nlohmann::json(*choice.rayquery_ms) : nlohmann::json()},
                       {"cached", choice.cached}};
  // Effective indirect-diffuse samples per cell after sharing vs the eye's own.
  double own = 0, shared = 0;
  for (int e = 0; e < 2; ++e) {
    const pipeline::IndirectSamples n = pipeline.indirect_samples(core::Eye(e));
    own += n.own;
    shared += n.effective;
  }
  j["stereo"] = {{"own_indirect_samples", own / 2}, {"effective_indirect_samples", shared / 2},
                 {"gain", own > 0 ? shared / own : 0.0}};

  const core::View left_view = pipeline.view(core::Eye::Left);
  const double ppd = core::flip_ppd(left_view);
  j["metrics"] = {{"tone_mapper", "ACES filmic, Narkowicz 2015 fit with HDR-FLIP's 0.6 input scale; sRGB OETF for "
                                  "PSNR, SSIM and flicker; display-linear for LDR-FLIP"},
                  {"exposure", kExposure},
                  {"ppd", ppd},
                  {"fovea_deg", core::acuity::kFoveaDeg},
                  {"band_deg", kBandDeg},
                  {"foveated_weights", "normalised acuity m(e), Koskela et al. 2018 P4 Eq. 1"}};
  const double neighbour = core::flip_neighbour_weight(ppd);
  j["metrics"]["flip_filters"] = {
      {"active", neighbour >= core::kFlipFiltersActiveWeight},
      {"neighbour_weight", neighbour},
      {"note", neighbour >= core::kFlipFiltersActiveWeight
                   ? "FLIP's spatial filters act at this display's pixels per degree"
                   : "FLIP's spatial filters are inactive at this display's pixels per degree (a pixel's neighbour "
                     "weighs below 1e-3 in the widest CSF filter): FLIP compares pixel by pixel here; use a preset of "
                     "6 ppd or more (fove0: 9.4) for scores that model the eye's contrast sensitivity"}};
  nlohmann::json ref_info, hidden_scored;
  bool transport_matched = true;
  for (int e = 0; e < 2; ++e) {
    const core::Eye eye = core::Eye(e);
    const char* name = e == 0 ? "left" : "right";
    const core::View v = pipeline.view(eye);
    const glm::dvec3 g = pipeline.distribution(eye).gaze();
    // The lens-hidden pixels (the display's lens, whether or not they were traced) are never scored.
    const std::vector<float> ecc = scored_eccentricity(v, g, lens[std::size_t(e)]);
    hidden_scored[name] = std::count_if(ecc.begin(), ecc.end(), [](float e) { return std::isnan(e); });
    nlohmann::json s;
    s["gaze"] = {g.x, g.y, g.z};  // view space, as the grid used it
    s["temporal_error"] = pipeline.temporal_error(eye);
    if (still[e].size() >= 2) {
      add_flicker(s, still[e], ecc);
    } else {
      s["flicker"] = nullptr;
      s["flicker_frames"] = still[e].size();
      s["flicker_note"] = "the gaze moved between the last two frames: no still frames to measure flicker over";
    }
    if (ref_spp > 0 || !ref_dir.empty()) {
      // Renders (or finds) this eye's reference of `request`, written next to the frames as
      // reference_<eye><suffix>.exr; describes it in ref_info.
      const auto reference = [&](const ReferenceRequest& request, const std::string& suffix) {
        if (bar) std::fprintf(stderr, "reference%s %s eye, up to %ld spp...\n", suffix.c_str(), name, ref_spp);
        ReferenceRequest req = request;
        if (ref_window) req.window.discs = {{g, ref_window_deg}};
        CachedReference r = cached_reference(ctx, gpu_scene, v, eye, req);
        write_reference((out_dir / (std::string("reference_") + name + suffix + ".exr")).string(), r);
        return r;
      };
      const auto describe = [&](const CachedReference& r) {
        const nlohmann::json settings = core::parse_json(r.identity).value("settings", nlohmann::json());
        nlohmann::json d = {{"spp", r.result.spp},
                            {"pixel_rel_error", r.result.pixel_rel_error},
                            {"rel_error", r.result.rel_error},
                            {"key", r.key},
                            {"cached", r.from_cache},
                            {"seconds", r.result.seconds},
                            {"settings", settings},
                            {"window", window_json(r.window)}};
        const core::HdrFlip range = core::hdr_flip_exposures(r.result.image, r.valid);
        d["hdr_flip_exposures"] = {{"start", range.start_exposure},
                                   {"stop", range.stop_exposure},
                                   {"count", range.exposures},
                                   {"from", r.valid.empty() ? "whole image" : "window"}};
        return d;
      };
      CachedReference ref = loaded[e] ? std::move(*loaded[e]) : reference(ref_request, "");
      ref_info[name] = describe(ref);
      const nlohmann::json settings = ref_info[name]["settings"];
      renderer::PathConfig ref_transport;
      ref_transport.max_bounces = settings.value("bounces", -1);
      ref_transport.rr_start = settings.value("rr_start", 0u);
      const bool matched = ref_transport.max_bounces == transport.max_bounces && ref_transport.rr_start == transport.rr_start;
      ref_info[name]["transport"] = pipeline::transport_json(ref_transport, matched ? "the render's" : "another");
      if (!matched) {
        transport_matched = false;
        std::cerr << "warning: --reference " << ref_dir << ": the " << name << " reference traces "
                  << ref_info[name]["transport"].dump() << ", the render " << pipeline::transport_json(transport, "").dump()
                  << ": its scores compare different light transport (report.json: transport.matched false)\n";
      }
      add_quality(s, last[e], ref.result.image, ref.valid, ecc, ppd);
      if (full_gi_score) {
        nlohmann::json full;
        if (full_gi_is_matched) {
          full = s;
        } else {
          const CachedReference fr = reference(full_gi_request, "_full_gi");
          ref_info[name]["full_gi"] = describe(fr);
          add_quality(full, last[e], fr.result.image, fr.valid, ecc, ppd);
        }
        for (const char* k : {"gaze", "temporal_error", "flicker", "flicker_frames", "flicker_note", "fovea_flicker",
                              "foveated_flicker", "flicker_bands"})
          full.erase(k);
        s["full_gi"] = full;
      }
    }
    j["summary"][name] = s;
  }
  if (!ref_info.is_null()) j["metrics"]["reference"] = ref_info;
  if (recovery_frames > 0) j["recovery"] = recovery.to_json();
  j["metrics"]["hidden_pixels"] = {{"left", hidden_scored["left"]},
                                   {"right", hidden_scored["right"]},
                                   {"note", "the display lens' hidden area: never scored; the rendered image takes the "
                                            "reference's pixels there, so that no SSIM or FLIP neighbourhood sees the "
                                            "lens edge"}};
  j["transport"] = {{"render", pipeline::transport_json(transport, frame_config.bounces.from_albedo
                                                                      ? "auto: from the scene's albedo"
                                                                      : "--bounces")}};
  if (!ref_info.is_null()) {
    j["transport"]["reference"] = ref_info["left"]["transport"];
    j["transport"]["matched"] = transport_matched;
    if (full_gi_score)
      j["transport"]["full_gi"] = pipeline::transport_json(
          {.max_bounces = full_gi_request.settings.bounces, .rr_start = full_gi_request.settings.rr_start},
          "the scene's albedo (summary.*.full_gi)");
  }
  core::write_file_atomic((out_dir / "report.json").string(), j.dump(2) + "\n");
  std::cout << nlohmann::json{{"gpu_ms", j["gpu_ms"]}, {"cpu_ms", j["cpu_ms"]}}.dump() << "\n";
  return 0;
}

}  // namespace

FOVEA_COMMAND(render_command, "render", "foveated stereo path tracing + reconstruction; PNGs, EXR, report.json", run);

}  // namespace fovea::tools::cmd_render
