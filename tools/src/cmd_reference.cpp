// fovea reference: progressive Cartesian path-traced reference image of one eye.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/output_path.hpp"
#include "fovea/core/image.hpp"
#include "fovea/renderer/path_tracer.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/renderer/reference.hpp"
#include "fovea/renderer/trace_choice.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "reference_cache.hpp"

namespace fovea::tools::cmd_reference {
namespace {

constexpr const char* kHelp = R"(usage: fovea reference --scene S --out F.exr|F.png [options]

Renders one eye's view of a scene progressively on a Cartesian grid (one jittered
sample per pixel and pass) until --spp samples per pixel, or earlier once a relative
standard error falls to its target. Writes the linear image as OpenEXR (32-bit float),
its description F.json (key, settings, statistics; what `fovea render --reference DIR`
checks) and a tone-mapped PNG (same name, other extension), and prints JSON:
{"spp", "mean_rgb", "rel_error", "pixel_rel_error", "seconds", "key", "cached", "window",
"pixels", "trace", "trace_why"}.
With --window only the pixels of the window are traced (the stop rules and statistics are
over them); the EXR's alpha is 1 on them and 0 elsewhere (RGB 0, not traced), the JSON
records the window, and `fovea render --reference DIR` scores only what they cover.
The result is kept in a cache keyed by the scene's bytes, the view, these settings, the
window and the renderer; the same request again reads it instead of rendering, and an entry
of the whole view with the same settings serves a window request. The defaults are those of
`fovea render --reference SPP` (--spp SPP --until-pixel-rel-error as its --reference-error),
so either command reuses the other's references.

  --scene S             cornell | furnace | glossy-spheres | stereo-occluders | default,
                        or a .gltf/.glb/.obj file [default]
  --trace auto|rayquery|compute
                        ray queries through the device's acceleration structure, or the
                        compute BVH traversal; auto: the faster of the two on this device,
                        measured once per device and driver and cached [auto]
  --display NAME|FILE   display preset (fove0, vive, modern, wide, small, tiny) or JSON [small]
  --eye left|right      which eye; it sits ipd/2 beside the scene's camera [left]
  --spp N               samples per pixel to stop at [256]
  --until-rel-error X   stop once the image mean's relative standard error is <= X; 0: off [0]
  --until-pixel-rel-error X  stop once the RMS of the per-pixel standard errors over the
                        mean luminance is <= X; 0: off [0.02]
  --batch N             samples per pixel per progressive pass [16]
  --bounces N|auto      BSDF-sampled bounces after the primary hit; -1 = unlimited
                        (with Russian roulette); auto: from the scene's albedo, until a
                        path keeps at most 0.1% of its light [auto]
  --rr-start N|auto     bounce from which Russian roulette applies; auto: once the mean
                        throughput is halved, from the scene's mean albedo [auto]
  --window DISC[;DISC...]  render only the union of discs, DISC = CENTRE@R: the pixels
                        whose centre lies within R degrees of CENTRE, a view-space direction
                        X,Y,Z (-Z forward, +Y up; `fovea render` reports each eye's gaze)
                        or a display pixel px:X,Y (origin top-left) [the whole view]
  --reference-cache DIR|off  the cache [$XDG_CACHE_HOME/fovea/references]
  --out F               output path ending in .exr or .png (all three are written)
  --quiet               no progress bar
  --help                this text

Exit status: 0 on success, 2 on invalid arguments or scene files, 1 on other errors.
)";

void progress_bar(const renderer::ReferenceProgress& p, std::uint32_t total) {
  const int width = 30;
  const int fill = int(double(width) * p.spp / std::max<std::uint32_t>(total, 1));
  std::fprintf(stderr, "\r[%s%s] %u/%u spp  pixel rel. error %s  %.1f s", std::string(std::size_t(fill), '#').c_str(),
               std::string(std::size_t(width - fill), ' ').c_str(), p.spp, total,
               std::isnan(p.pixel_rel_error) ? "  -   " : (std::to_string(p.pixel_rel_error).substr(0, 8)).c_str(),
               p.seconds);
  std::fflush(stderr);
}

int run(std::vector<std::string> argv) {
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") {
      std::cout << kHelp;
      return 0;
    }
  const Args args(argv, {"scene", "display", "eye", "spp", "until-rel-error", "until-pixel-rel-error", "batch", "bounces", "rr-start",
                         "reference-cache", "out", "trace", "window"},
                  {"quiet"});
  const auto out = args.opt("out");
  if (!out) throw core::InputError("--out F.exr|F.png is required (see --help)");
  const std::filesystem::path out_path(*out);
  const std::string ext = out_path.extension().string();
  if (ext != ".exr" && ext != ".png") throw core::InputError("--out must end in .exr or .png, got \"" + *out + "\"");
  core::prepare_output_file(*out, "--out");
  std::filesystem::path exr = out_path, png = out_path;
  exr.replace_extension(".exr");
  png.replace_extension(".png");

  const renderer::Scene scene = renderer::load_scene(args.str("scene", "default"));
  const ReferenceSettings defaults = reference_defaults(scene);
  const auto int_or_auto = [&](const char* name, long automatic) {
    return args.str(name, "auto") == "auto" ? automatic : args.integer(name, automatic);
  };
  const long spp = args.integer("spp", defaults.max_spp), batch = args.integer("batch", defaults.batch),
             bounces = int_or_auto("bounces", defaults.bounces), rr = int_or_auto("rr-start", defaults.rr_start);
  if (spp < 1 || spp > (1L << 24)) throw core::InputError("--spp must be in 1..16777216");
  if (batch < 1 || batch > 4096) throw core::InputError("--batch must be in 1..4096");
  if (bounces < -1 || bounces > 256) throw core::InputError("--bounces must be -1 (unlimited) or 0..256");
  if (rr < 0 || rr > 1000) throw core::InputError("--rr-start must be in 0..1000");
  const double until = args.num("until-rel-error", defaults.until_rel_error),
               until_pixel = args.num("until-pixel-rel-error", defaults.until_pixel_rel_error);
  if (!(until >= 0) || !std::isfinite(until)) throw core::InputError("--until-rel-error must be >= 0 (0: off)");
  if (!(until_pixel >= 0) || !std::isfinite(until_pixel))
    throw core::InputError("--until-pixel-rel-error must be >= 0 (0: off)");
  const auto cache_opt = args.opt("reference-cache");
  const std::string cache = reference_cache_arg(cache_opt ? &*cache_opt : nullptr);

  const core::DisplayPreset display = core::load_display(args.str("display", core::kDefaultDisplay));
  const core::Eye eye = core::parse_eye(args.str("eye", "left"));
  const renderer::Tracing tracing = renderer::parse_tracing(args.str("trace", "auto"));
  for (const auto& w : scene.warnings) std::cerr << "warning: " << w << "\n";

  const core::View view = core::stereo_views(display, scene.camera)[eye];
  renderer::ReferenceWindow window;
  if (auto w = args.opt("window")) window = parse_window(*w, view, "--window");

  gpu::Context ctx;
  const renderer::TraceChoice choice = renderer::choose_tracing(ctx, tracing, renderer::default_trace_choice_cache());
  renderer::GpuScene gs(ctx, scene, {}, choice.tracing);
  ReferenceRequest req;
  req.scene = args.str("scene", "default");
  req.settings = defaults;
  req.settings.max_spp = std::uint32_t(spp);
  req.settings.batch = std::uint32_t(batch);
  req.settings.bounces = int(bounces);
  req.settings.rr_start = std::uint32_t(rr);
  req.settings.until_rel_error = until;
  req.settings.until_pixel_rel_error = until_pixel;
  req.window = window;
  req.cache_dir = cache;
  const bool bar = !args.has("quiet") && stderr_is_tty();
  const CachedReference c = cached_reference(ctx, gs, view, eye, req, [&](const renderer::ReferenceProgress& p) {
    if (bar) progress_bar(p, req.settings.max_spp);
  });
  if (bar) std::fprintf(stderr, "\n");
  const renderer::ReferenceResult& r = c.result;

  write_reference(exr.string(), c);
  core::write_png(png.string(), renderer::tone_map(r.image));
  nlohmann::json j;
  j["spp"] = r.spp;
  j["bounces"] = bounces;
  j["rr_start"] = rr;
  j["mean_rgb"] = {r.mean_rgb.x, r.mean_rgb.y, r.mean_rgb.z};
  j["rel_error"] = r.rel_error;
  j["pixel_rel_error"] = r.pixel_rel_error;
  j["seconds"] = r.seconds;
  j["key"] = c.key;
  j["cached"] = c.from_cache;
  j["trace"] = renderer::tracing_name(gs.tracing());
  j["trace_why"] = choice.why;
  // What the image holds: a whole-view entry may have served a window request.
  j["window"] = window_json(c.window);
  j["pixels"] = c.valid.empty() ? r.image.pixels.size() : std::size_t(std::count(c.valid.begin(), c.valid.end(), true));
  std::cout << j.dump() << "\n";
  return 0;
}

}  // namespace

FOVEA_COMMAND(reference_command, "reference", "progressive Cartesian path-traced reference image (EXR + PNG)", run);

}  // namespace fovea::tools::cmd_reference
