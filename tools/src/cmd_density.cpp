// fovea density: the sample density a distribution puts on the display, as a heat map
// (samples per display pixel, log scale) and as JSON bands against the target.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fovea/core/acuity.hpp"
#include "fovea/core/density_report.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/output_path.hpp"
#include "fovea/core/image.hpp"
#include "gaze_arg.hpp"

namespace fovea::tools {
namespace {

constexpr const char* kHelp = R"(usage: fovea density [options]

Shows how a sample distribution spreads its samples over one eye's display.

  --display NAME|FILE   display preset (fove0, vive, modern, small, tiny) or JSON file [small]
  --eye left|right      which eye's view [left]
  --gaze X,Y            gaze in normalised screen coordinates, origin top-left [0.5,0.5]
  --gaze-dir x,y,z      gaze as a view-space direction (OpenXR: -Z forward, +Y up)
  --distribution D      visual-polar | paper-visual-polar | cartesian | cartesian-uniform |
                        linear-falloff | log-polar [visual-polar]
  --budget F            grid samples as a fraction of display pixels, 0.01..1 [0.39]
  --margin DEG          fovea margin for tracker error (visual-polar) [1]
  --gamma 1|2           acuity exponent: 1 = the papers' radial pdf, 2 = 2-D Nyquist [1]
  --cap K               at most K samples per display pixel [1]
  --aniso A             bound on the cells' phi/rho spacing ratio [2]
  --staircase           P5's rows-constant-per-32-columns layout (visual-polar)
  --out PNG             heat map of samples per display pixel (log scale 1e-3..10,
                        colour bar below; gaze cross and fovea circle marked)
  --json                print the measurement as JSON on stdout
  --help                this text

Exit status: 0 on success, 2 on invalid arguments.
)";

void mark(core::Image& img, int x, int y, glm::vec4 c) {
  if (x >= 0 && y >= 0 && x < img.width && y < img.height) img.at(x, y) = c;
}

core::Image heat_map(const core::SampleDistribution& d) {
  const core::View& v = d.view();
  const int bar = std::max(6, v.height() / 40);
  core::Image img(v.width(), v.height() + bar);
  const double lo = -3, hi = 1;  // log10 spp
  const double fovea = core::acuity::kFoveaDeg + d.params().margin_deg;
  const glm::dvec2 gp = v.dir_to_pixel(d.gaze()).value_or(glm::dvec2(-100));
  for (int y = 0; y < v.height(); ++y)
    for (int x = 0; x < v.width(); ++x) {
      const glm::dvec2 px{x + 0.5, y + 0.5};
      const double spp = d.samples_per_pixel(px);
      const double t = spp > 0 ? (std::log10(spp) - lo) / (hi - lo) : 0;
      img.at(x, y) = core::colormap_inferno(float(t));
      // The fovea circle: pixels whose eccentricity crosses the radius.
      const glm::dvec3 dir = v.pixel_to_dir(px);
      const double e = core::angle_deg(dir, d.gaze());
      const double step = 1.0 / std::sqrt(v.pixels_per_deg2(dir));  // degrees per pixel
      if (std::abs(e - fovea) < 0.5 * step) img.at(x, y) = {1, 1, 1, 1};
    }
  const int arm = std::max(3, v.width() / 60);
  for (int k = -arm; k <= arm; ++k)
    for (int w = -1; w <= 1; ++w) {
      mark(img, int(gp.x) + k, int(gp.y) + w, {0.2f, 1, 0.3f, 1});
      mark(img, int(gp.x) + w, int(gp.y) + k, {0.2f, 1, 0.3f, 1});
    }
  for (int x = 0; x < v.width(); ++x) {
    const float t = (x + 0.5f) / v.width();
    const double decade = t * (hi - lo);
    const bool tick = std::abs(decade - std::round(decade)) * v.width() / (hi - lo) < 1.0;
    for (int y = v.height(); y < v.height() + bar; ++y)
      img.at(x, y) = (tick && y < v.height() + bar / 2) ? glm::vec4(1) : core::colormap_inferno(t);
  }
  return img;
}

int run(std::vector<std::string> argv) {
  if (std::find(argv.begin(), argv.end(), "--help") != argv.end()) {
    std::cout << kHelp;
    return 0;
  }
  const Args a(argv,
               {"display", "eye", "gaze", "gaze-dir", "distribution", "budget", "margin", "gamma", "cap", "aniso", "out"},
               {"json", "staircase"});
  const core::DisplayPreset preset = core::load_display(a.str("display", "small"));
  const core::Eye eye = core::parse_eye(a.str("eye", "left"));
  const core::View view = preset.view(eye);

  core::DistributionParams p;
  p.kind = core::parse_distribution(a.str("distribution", "visual-polar"));
  p.budget = a.num("budget", p.budget);
  p.margin_deg = a.num("margin", p.margin_deg);
  p.gamma = a.num("gamma", p.gamma);
  p.cap = a.num("cap", p.cap);
  p.aniso = a.num("aniso", p.aniso);
  p.staircase = a.has("staircase");
  p.display = preset.origin;
  const glm::dvec3 gaze = parse_gaze(a, view);

  auto dist = core::make_distribution(view, p);
  const core::GazeStatus st = dist->set_frame(gaze);
  const core::DensityReport r = core::measure_density(*dist);
  const glm::dvec2 gp = view.dir_to_pixel(st.used).value_or(glm::dvec2(0));

  if (auto out = a.opt("out")) {
    core::prepare_output_file(*out, "--out");
    core::write_png(*out, heat_map(*dist));
  }
  if (st.clamped) std::cerr << "fovea density: gaze outside the view, clamped to its border\n";
  if (st.fallback) std::cerr << "fovea density: gaze unusable (NaN, zero or backwards), using the view centre\n";

  if (a.has("json")) {
    nlohmann::ordered_json j;
    j["distribution"] = core::distribution_name(p.kind);
    j["display"] = preset.name;
    j["eye"] = core::eye_name(eye);
    j["gaze"] = {{"x", gp.x / view.width()}, {"y", gp.y / view.height()}, {"clamped", st.clamped},
                 {"fallback", st.fallback}};
    j["grid"] = {{"columns", r.columns},
                 {"rows", r.rows},
                 {"fill", r.fill},
                 {"padded_columns", dist->padded_columns()},
                 {"padded_rows", dist->padded_rows()}};
    j["samples_grid"] = r.grid_samples;
    j["samples_traced"] = r.traced;
    j["samples_offscreen"] = r.offscreen;
    j["budget_fraction"] = p.budget;
    j["traced_fraction"] = double(r.traced) / (double(view.width()) * view.height());
    j["fovea_spp"] = r.fovea_spp;
    auto& bands = j["bands"] = nlohmann::ordered_json::array();
    for (const auto& b : r.bands)
      bands.push_back({{"e_min", b.e_min},
                       {"e_max", b.e_max},
                       {"samples", b.samples},
                       {"samples_per_deg2", b.samples_per_deg2},
                       {"target_samples_per_deg2", b.target_samples_per_deg2},
                       {"display_pixels_per_deg2", b.display_pixels_per_deg2}});
    std::cout << j.dump(2) << "\n";
  }
  return 0;
}

}  // namespace

FOVEA_COMMAND(density_command, "density", "heat map and JSON of a sample distribution's density", run);

}  // namespace fovea::tools
