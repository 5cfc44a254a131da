// fovea density: the sample density a distribution puts on the display, as a heat map
// (samples per display pixel, log scale) and as JSON bands against the target.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fovea/core/acuity.hpp"
#include "fovea/core/density_report.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/core/output_path.hpp"
#include "fovea/core/image.hpp"
#include "figures.hpp"
#include "gaze_arg.hpp"

namespace fovea::tools::cmd_density {
namespace {

constexpr const char* kHelp = R"(usage: fovea density [options]

Shows how a sample distribution spreads its samples over one eye's display.

  --display NAME|FILE   display preset (fove0, vive, modern, wide, small, tiny) or JSON file [small]
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
  --hidden-area         cull with the lens' hidden area as `fovea render` does: its cells
                        are not traced and the budget counts the pixels it leaves visible
  --out PNG             heat map of samples per display pixel (log scale 1e-3..10, numbered
                        colour bar; gaze cross and fovea edge marked), drawn by matplotlib
                        as PNG and SVG from the data written beside them (same stem, .json
                        and .npy; docs/figures.md)
  --json                print the measurement as JSON on stdout
  --help                this text

Exit status: 0 on success, 2 on invalid arguments.
)";

// The figure's data: OUT's stem + .npy, float32 [2, height, width]: log10 of the samples per
// display pixel (clamped to kLogRange) and each pixel's eccentricity from the gaze (deg);
// and OUT's stem + .json: what tools/plots/density.py needs besides (gaze, fovea radius).
// The figure: the heat map with a numbered colour bar, gaze and fovea marked (PNG and SVG).
constexpr double kLogRange[2] = {-3, 1};

void write_npy(const std::string& path, const std::vector<float>& values, int layers, int height, int width) {
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(layers) + ", " +
                       std::to_string(height) + ", " + std::to_string(width) + "), }";
  header.append(63 - (10 + header.size()) % 64, ' ');  // NPY 1.0: magic, version, length, header, '\n' to 64 bytes
  header += '\n';
  std::string bytes("\x93NUMPY\x01\x00", 8);
  bytes += char(header.size() & 0xff);
  bytes += char(header.size() >> 8);
  bytes += header;
  // Little-endian float32, as on every host the project builds for (x86-64, arm64).
  bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
  core::write_file_atomic(path, bytes);
}

void write_figure(const std::string& out_png, const core::SampleDistribution& d, const std::string& title) {
  const core::View& v = d.view();
  const int w = v.width(), h = v.height();
  std::vector<float> values(2 * std::size_t(w) * std::size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::dvec2 px{x + 0.5, y + 0.5};
      const double spp = d.samples_per_pixel(px);
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      values[i] = float(spp > 0 ? std::clamp(std::log10(spp), kLogRange[0], kLogRange[1]) : kLogRange[0]);
      values[std::size_t(w) * std::size_t(h) + i] = float(core::angle_deg(v.pixel_to_dir(px), d.gaze()));
    }
  const std::filesystem::path stem = std::filesystem::path(out_png).replace_extension();
  write_npy(stem.string() + ".npy", values, 2, h, w);
  const glm::dvec2 gp = v.dir_to_pixel(d.gaze()).value_or(glm::dvec2(w / 2.0, h / 2.0));
  nlohmann::ordered_json j;
  j["figure"] = "density";
  j["file"] = stem.filename().string();
  j["array"] = stem.filename().string() + ".npy";
  j["title"] = title;
  j["gaze_px"] = {gp.x, gp.y};
  j["fovea_deg"] = core::acuity::kFoveaDeg + d.params().margin_deg;
  j["range_log10"] = kLogRange;
  const std::string data = stem.string() + ".json";
  core::write_file_atomic(data, j.dump(2) + "\n");
  draw_figures("density", data, std::cerr);
}

int run(std::vector<std::string> argv) {
  if (std::find(argv.begin(), argv.end(), "--help") != argv.end()) {
    std::cout << kHelp;
    return 0;
  }
  const Args a(argv,
               {"display", "eye", "gaze", "gaze-dir", "distribution", "budget", "margin", "gamma", "cap", "aniso", "out"},
               {"json", "staircase", "hidden-area"});
  const core::DisplayPreset preset = core::load_display(a.str("display", core::kDefaultDisplay));
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

  // As `fovea render` culls: the grid laid out for the pixels the lens leaves.
  std::optional<core::ViewMask> mask;
  if (a.has("hidden-area")) mask = core::EyeOptics(preset, eye).view_mask();
  auto dist = core::make_distribution(view, p, mask ? &*mask : nullptr);
  const core::GazeStatus st = dist->set_frame(gaze);
  const core::DensityReport r = core::measure_density(*dist);
  const glm::dvec2 gp = view.dir_to_pixel(st.used).value_or(glm::dvec2(0));

  if (auto out = a.opt("out")) {
    core::prepare_output_file(*out, "--out");
    char title[200];
    std::snprintf(title, sizeof title, "%s, %s eye %dx%d px, budget %.2f: samples per display pixel",
                  core::distribution_name(p.kind), core::eye_name(eye), view.width(), view.height(), p.budget);
    write_figure(*out, *dist, title);
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
    j["samples_hidden"] = r.hidden;
    j["budget_fraction"] = p.budget;
    j["budget_samples"] = dist->budget_samples();
    j["traced_fraction"] = double(r.traced) / (double(view.width()) * view.height());
    j["traced_of_budget"] = double(r.traced) / dist->budget_samples();
    if (const auto vp = core::visual_polar_state(*dist))
      j["visual_polar"] = {{"sigma0", vp->sigma0},
                           {"row_scale", vp->row_scale},
                           {"sigma_disp", vp->sigma_disp},
                           {"ring_cap", vp->ring_cap}};
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

}  // namespace fovea::tools::cmd_density
