#pragma once
// What `fovea latency` reports from timing records (a simulation's or an OpenXR session's):
// distributions of tracker delay, gaze-to-photon, motion-to-photon and each stage, missed
// frames, and — where the records carry the truth — the foveal error at photon time; plus
// the charts of them (drawn by matplotlib, docs/figures.md). docs/latency.md.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "latency/simulate.hpp"
#include "sweep/plot.hpp"

namespace fovea::latency {

struct Distribution {
  std::size_t n = 0;
  double median = 0, p95 = 0, p99 = 0, max = 0;
};
// Nearest-rank percentiles of the finite values.
Distribution distribution(std::vector<double> v);
nlohmann::json to_json(const Distribution& d);

// Per record (ms): measured tracker delay (receive − sample), gaze-to-photon (left eye's
// mid-row photon time − sample; the vsync without photon times), motion-to-photon (photon
// − head pose time). Records lacking the times are skipped.
struct Latencies {
  std::vector<double> tracker_delay_ms, gaze_to_photon_ms, motion_to_photon_ms;
};
Latencies latencies(const std::vector<xrcommon::TimingRecord>& records);

// The panel's foveal error at every vsync with a tracked true eye, degrees.
std::vector<double> shown_errors(const Simulation& sim);

// Foveal-error figures from errors in degrees: distribution, mean, fraction above 1°, 2°, 5°.
nlohmann::json error_summary(const std::vector<double>& error_deg);

// The summary of records; `sim` (optional) adds the per-vsync foveal error, saccades and
// recovery times.
nlohmann::json summarize(const std::vector<xrcommon::TimingRecord>& records, const Simulation* sim);

// The charts: latency (distributions), stages, and with the truth foveal_error (over
// time, saccade onsets marked, broken where no true eye was shown).
std::vector<sweep::Chart> plots(const std::vector<xrcommon::TimingRecord>& records, const Simulation* sim,
                                const std::string& note);

struct SweepPoint {
  double inject_ms = 0;
  nlohmann::json error;      // error_summary over the panel's vsyncs
  double gaze_to_photon_median_ms = 0;
  double recovery_median_ms = 0;
  std::size_t recovered = 0;
  // Quality against the converged reference within quality_radius_deg of the true gaze.
  std::optional<double> fovea_psnr_db, fovea_hdr_flip;
  double quality_radius_deg = 0;
  std::size_t quality_frames = 0, quality_saccades = 0;  // what the quality is a mean over
};
// sweep_error (foveal error vs injected latency, n per point) and, with quality,
// sweep_quality (tone-mapped PSNR) and sweep_flip (HDR-FLIP), frames and saccades per point.
std::vector<sweep::Chart> sweep_plots(const std::vector<SweepPoint>& points, const std::string& note);

}  // namespace fovea::latency
