#include "render_setup.hpp"

#include <algorithm>
#include <cstdio>

#include <nlohmann/json.hpp>

namespace fovea::tools {

pipeline::FrameConfig frame_config_of(const Args& args, const std::vector<std::string>& not_frame) {
  pipeline::FrameConfig c;
  for (const std::string& name : pipeline::frame_option_names())
    if (std::find(not_frame.begin(), not_frame.end(), name) == not_frame.end())
      if (auto v = args.opt(name)) pipeline::apply_frame_option(c, name, *v, "--" + name);
  try {
    pipeline::finish(c, args.has("budget"));
  } catch (const core::InputError& e) {
    throw core::InputError(std::string("--") + e.what());  // "--budget: must be in ..."
  }
  return c;
}

namespace {

// Each frame option's help, as `--help` prints it, without its default: in the order the
// commands list them.
struct OptionHelp {
  const char* name;
  const char* text;
};
constexpr OptionHelp kFrameOptionsHelp[] = {
    {"distribution",
     "  --distribution D      visual-polar | paper-visual-polar | cartesian | cartesian-uniform |\n"
     "                        linear-falloff | log-polar"},
    {"budget",
     "  --budget B            grid samples as a fraction of display pixels, met within 5% or\n"
     "                        refused with exit 2 naming what the distribution reaches\n"
     "                        (cartesian: 1 only)"},
    {"cap",
     "  --cap K               visual-polar: at most K samples per display pixel, the fovea's\n"
     "                        density (κ, docs/visual-polar.md), in (0, 16]"},
    {"jitter", "  --jitter on|off       per-frame sub-cell jitter (Halton 2, 3) of every grid"},
    {"denoiser", "  --denoiser D          bmfr | none (accumulation only)"},
    {"bmfr-precision", "  --bmfr-precision P    fp32 | fp16: storage of BMFR's regression matrix"},
    {"stereo-share", "  --stereo-share M      off | gather | alternate"},
    {"bounces",
     "  --bounces N|auto      BSDF-sampled bounces after the primary hit, no Russian roulette (1:\n"
     "                        the BMFR/P5 configuration); auto: the bounce limit and Russian\n"
     "                        roulette from the scene's albedo, i.e. full global illumination as\n"
     "                        `fovea reference` traces it"},
    {"landing-spp",
     "  --landing-spp N       samples per cell in a new fovea's first 4 frames after a gaze jump\n"
     "                        of 5° or more (1..8; 1: one, as every other frame)"},
    {"pixel-albedo",
     "  --pixel-albedo on|off textures at the display's resolution in the fovea: each display\n"
     "                        pixel's own first hit re-modulates it (scenes with textures)"},
    {"lattice-blur",
     "  --lattice-blur on|off polar grids: where a cell spans more than 1.5 display pixels, the\n"
     "                        cubic B-spline over four cells instead of the tent over two, so that\n"
     "                        their lattice (rings about the gaze, spokes) does not show: smoother\n"
     "                        and less detailed (docs/reconstruction.md, \"The lattice's rings\") [on]"},
    {"raster-filter",
     "  --raster-filter box|gaussian\n"
     "                        cartesian: each display pixel its own cell (box), or a Gaussian\n"
     "                        over its 3x3 cells (sigma 0.5 px, radius 1.5: pbrt-v4's default),\n"
     "                        which averages about as much noise as the tent over polar cells"},
    {"seed",
     "  --seed N              noise seed: another N, another noise realisation of the same frames\n"
     "                        (path tracing and BMFR keyed by frame + 1024·N; gaze and jitter\n"
     "                        unchanged)"},
    {"trace",
     "  --trace auto|rayquery|compute\n"
     "                        ray queries through the device's acceleration structure, or the\n"
     "                        compute BVH traversal; auto: the faster of the two on this device,\n"
     "                        measured once per device and driver and cached"},
};

// A default as the help shows it: 0.39, 1, visual-polar.
std::string default_text(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v.get<double>());
    return buf;
  }
  return v.dump();
}

}  // namespace

std::string frame_options_help(const std::vector<std::string>& not_frame) {
  const nlohmann::json defaults = pipeline::to_json(pipeline::FrameConfig{});
  std::string out;
  for (const auto& [name, text] : kFrameOptionsHelp)
    if (std::find(not_frame.begin(), not_frame.end(), name) == not_frame.end())
      out += std::string(text) + " [" + default_text(defaults.at(name)) + "]\n";
  return out;
}

}  // namespace fovea::tools
