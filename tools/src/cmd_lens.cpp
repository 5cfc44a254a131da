// fovea lens: a display preset's optics — a grid warped through the lens (per colour
// channel, so chromatic aberration shows as fringes), the hidden area, and as JSON the
// hidden fraction, the inverse optics' round-trip error and the path-tracing samples the
// hidden area saves on the default Visual-Polar grid.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <iostream>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fovea/compositor/distortion.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/output_path.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/core/hidden_area.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/lens.hpp"

namespace fovea::tools::cmd_lens {
namespace {

constexpr const char* kHelp = R"(usage: fovea lens [options]

Pictures and measures a display preset's lens: both eyes' panels side by side, showing a
grid of view directions (lines every 5 degrees) warped through the optics, each colour
through its own channel's optics (chromatic aberration shows as fringes), the hidden area
in dark red.

  --display NAME|FILE   display preset (fove0, vive, modern, wide, small, tiny) or JSON file [small]
  --channel r|g|b       use one channel's optics for all colours (that channel's distortion)
  --grid                overlay the panel's own straight grid (every 1/16 of the panel)
  --out PNG             picture to write [out/lens/lens-<display>.png]
  --json                print {"display", "eyes": {"left": {"hidden_fraction",
                        "max_roundtrip_px", "samples_saved_fraction", "samples_hidden"},
                        "right": {...}}}
  --help                this text

hidden_fraction: display pixels no one sees. max_roundtrip_px: the largest distance between
a visible display pixel and forward-then-inverse optics of it, over all channels.
samples_saved_fraction, samples_hidden: of the default Visual-Polar grid's on-screen samples
(gaze straight ahead), the fraction and the number of cells the path tracer skips because the
lens hides them (the view mask fovea render culls with).

Exit status: 0 on success, 2 on invalid arguments.
)";

core::Image eye_picture(const core::HiddenAreaMask& mask, compositor::ChannelSelect select, bool panel_grid) {
  core::Image img = compositor::distort_reference(mask, compositor::direction_grid(mask.lens().view()), select);
  const int W = img.width, H = img.height;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      glm::vec4& p = img.at(x, y);
      if (mask.hidden(x, y)) p = {0.18f, 0.0f, 0.0f, 1};
      if (panel_grid && ((x * 16) % W < 16 || (y * 16) % H < 16)) p = glm::mix(p, glm::vec4(0.2f, 0.4f, 1, 1), 0.5f);
    }
  return img;
}

// Largest forward∘inverse distance in pixels over visible display pixels and channels.
double max_roundtrip_px(const core::HiddenAreaMask& mask) {
  const core::Lens& lens = mask.lens();
  const int W = mask.width(), H = mask.height();
  const unsigned threads = std::max(1u, std::min(4u, std::thread::hardware_concurrency()));
  std::vector<double> worst(threads, 0);
  std::vector<std::thread> pool;
  std::atomic<bool> failed{false};
  for (unsigned t = 0; t < threads; ++t)
    pool.emplace_back([&, t] {
      for (int y = int(t); y < H; y += int(threads))
        for (int x = 0; x < W; ++x) {
          if (mask.hidden(x, y)) continue;
          const glm::dvec2 uv((x + 0.5) / W, (y + 0.5) / H);
          const core::LensSample s = lens.forward(uv);
          for (int c = 0; c < 3; ++c) {
            const auto back = lens.inverse(c, s.tangent[c]);
            if (!back) {
              failed = true;
              continue;
            }
            worst[t] = std::max(worst[t], glm::length((*back - uv) * glm::dvec2(W, H)));
          }
        }
    });
  for (auto& th : pool) th.join();
  if (failed) return std::numeric_limits<double>::infinity();  // an inverse failed where forward is visible
  return *std::max_element(worst.begin(), worst.end());
}

// The default Visual-Polar grid at centre gaze with the view mask `fovea render` culls with.
struct SamplesHidden {
  double fraction = 0;      // of the on-screen samples
  std::int64_t count = 0;   // cells
};

SamplesHidden samples_hidden(const core::EyeOptics& optics, const std::string& display) {
  core::DistributionParams params;
  params.display = display;
  const core::ViewMask mask = optics.view_mask();
  auto dist = core::make_distribution(optics.view(), params, &mask);
  dist->set_frame({0, 0, -1});
  std::size_t traced = 0, hidden = 0;
  for (int row = 0; row < dist->rows(); ++row)
    for (int col = 0; col < dist->columns(); ++col) {
      const std::uint32_t f = dist->sample_at(col, row, {0, 0}).flags;
      if (f & (shaders::kCellClipped | shaders::kCellPadding | shaders::kCellKilled | shaders::kCellOffscreen))
        continue;
      (f & shaders::kCellHidden ? hidden : traced) += 1;
    }
  return {traced + hidden ? double(hidden) / double(traced + hidden) : 0.0, std::int64_t(hidden)};
}

int run(std::vector<std::string> argv) {
  for (const auto& a : argv)
    if (a == "--help" || a == "-h") {
      std::cout << kHelp;
      return 0;
    }
  const Args args(argv, {"display", "channel", "out"}, {"grid", "json"});
  const core::DisplayPreset d = core::load_display(args.str("display", core::kDefaultDisplay));
  compositor::ChannelSelect select = compositor::ChannelSelect::All;
  if (auto c = args.opt("channel")) {
    if (*c == "r") select = compositor::ChannelSelect::Red;
    else if (*c == "g") select = compositor::ChannelSelect::Green;
    else if (*c == "b") select = compositor::ChannelSelect::Blue;
    else throw core::InputError("option --channel: expected r, g or b, got \"" + *c + "\"");
  }
  // Like every command's output, under out/ unless --out says otherwise.
  const std::string out = args.str("out", "out/lens/lens-" + d.name + ".png");
  core::prepare_output_file(out, "--out");

  nlohmann::ordered_json eyes;
  core::Image panel(2 * d.width, d.height);
  for (core::Eye eye : {core::Eye::Left, core::Eye::Right}) {
    const core::Lens lens = core::Lens::for_eye(d, eye);
    for (const auto& n : lens.notes()) std::cerr << "fovea lens: note: " << n << "\n";
    const core::EyeOptics optics(lens);
    const core::HiddenAreaMask& mask = optics.hidden();
    const core::Image img = eye_picture(mask, select, args.has("grid"));
    const int x0 = eye == core::Eye::Left ? 0 : d.width;
    for (int y = 0; y < d.height; ++y)
      for (int x = 0; x < d.width; ++x) panel.at(x0 + x, y) = img.at(x, y);
    if (args.has("json")) {
      const SamplesHidden saved = samples_hidden(optics, d.origin);
      eyes[core::eye_name(eye)] = {{"hidden_fraction", mask.hidden_fraction()},
                                   {"max_roundtrip_px", max_roundtrip_px(mask)},
                                   {"samples_saved_fraction", saved.fraction},
                                   {"samples_hidden", saved.count}};
    }
  }
  core::write_png(out, panel);
  if (args.has("json")) {
    nlohmann::ordered_json j = {{"display", d.name}, {"eyes", eyes}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::cerr << "fovea lens: wrote " << out << "\n";
  }
  return 0;
}

}  // namespace

FOVEA_COMMAND(lens_command, "lens", "picture and measure a display preset's lens optics and hidden area", run);

}  // namespace fovea::tools::cmd_lens
