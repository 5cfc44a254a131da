// Foveal error after saccades with and without gaze prediction (docs/gaze.md, "Prediction,
// measured"): a modelled tracker (default fove0) over a true eye, a fixed render + display
// latency, each prediction mode. Prints a Markdown table. Deterministic (virtual time).
//   fovea_predict_table [--latency MS] [--tracker PRESET] [--seconds S] TRUTH_URI...
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "fovea/core/duration.hpp"
#include "fovea/core/error.hpp"
#include "fovea/devices/compensation.hpp"

using namespace fovea;

int main(int argc, char** argv) {
  try {
    devices::CompensationParams p;
    std::vector<std::string> truths;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      const auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw core::InputError(a + " needs a value");
        return argv[++i];
      };
      if (a == "--latency") p.latency_ns = core::parse_duration_ns(value(), "--latency");
      else if (a == "--tracker") p.tracker = devices::tracker_preset(value());
      else if (a == "--seconds") p.seconds = std::atof(value().c_str());
      else if (!a.empty() && a[0] == '-') throw core::InputError("unknown option " + a);
      else truths.push_back(a);
    }
    if (truths.empty()) throw core::InputError("usage: fovea_predict_table [--latency T] [--tracker PRESET] [--seconds S] TRUTH_URI...");
    std::printf("tracker %s (%.0f Hz, delay %.1f ms), latency %.1f ms, display %.0f Hz, window after each landing %.0f ms\n\n",
                p.tracker.name.c_str(), p.tracker.rate_hz, core::ns_to_ms(p.tracker.delay_ns), core::ns_to_ms(p.latency_ns),
                p.display_hz, core::ns_to_ms(p.after_saccade_ns));
    std::printf("| true gaze | predict | saccades | frames after landing | mean | median | p95 | max | > 2° | all frames, mean |\n");
    std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const std::string& truth : truths)
      for (auto mode : {devices::PredictMode::None, devices::PredictMode::Linear, devices::PredictMode::Landing}) {
        const devices::FovealError e = devices::measure_foveal_error(truth, mode, p);
        std::printf("| `%s` | %s | %zu | %zu | %.2f° | %.2f° | %.2f° | %.2f° | %.0f%% | %.2f° |\n", truth.c_str(),
                    devices::predict_mode_name(mode), e.saccades, e.post_frames, e.mean_deg, e.p50_deg, e.p95_deg, e.max_deg,
                    100 * e.over_2deg, e.all_mean_deg);
      }
    return 0;
  } catch (const core::InputError& e) {
    std::fprintf(stderr, "fovea_predict_table: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fovea_predict_table: %s\n", e.what());
    return 1;
  }
}
