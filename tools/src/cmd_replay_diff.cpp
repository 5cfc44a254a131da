// fovea replay-diff A B: compares two `fovea render` output directories — per frame the gaze
// sample used, the gaze each eye was rendered with, eye poses and grid size (frames.jsonl;
// timings live apart in frame_times.jsonl), and the images both runs wrote — with tolerances. Exit 0 when they
// agree, 1 on a difference, 2 on unusable input: the regression check to run in CI.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/json.hpp"
#include "fovea/core/metrics.hpp"

namespace fovea::tools::cmd_replay_diff {
namespace {

namespace fs = std::filesystem;

const char* kHelp = R"(usage: fovea replay-diff A B [--gaze-tol-deg D] [--pose-tol T] [--psnr-min DB] [--json]
Compares two `fovea render --out` directories:
  frames.jsonl  same frames; per frame equal times, flags and grid size; gaze directions
                (sample and used) within --gaze-tol-deg [1e-6]; eye poses within --pose-tol
                (m, quaternion components) [1e-9] (timings are in frame_times.jsonl, not compared)
  *.png         every image present in both (frames, sbs): PSNR >= --psnr-min dB [60]
                (identical images: infinite); an image only in one run is a difference
Exit status: 0 equal within the tolerances, 1 different, 2 unusable input.
)";

std::vector<nlohmann::json> read_frames(const fs::path& dir) {
  const fs::path p = dir / "frames.jsonl";
  std::ifstream in(p);
  if (!in) throw core::InputError(p.string() + ": cannot open (not a `fovea render` output directory?)");
  std::vector<nlohmann::json> out;
  std::string line;
  for (std::size_t n = 1; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    try {
      out.push_back(core::parse_json(line));
    } catch (const nlohmann::json::exception& e) {
      throw core::InputError(p.string() + ":" + std::to_string(n) + ": invalid JSON: " + e.what());
    }
    if (!out.back().is_object()) throw core::InputError(p.string() + ":" + std::to_string(n) + ": not a JSON object");
  }
  return out;
}

// Angle between two direction arrays (degrees); null on either side compares equal only to null.
double angle(const nlohmann::json& a, const nlohmann::json& b) {
  if (a.is_null() || b.is_null()) return a.is_null() && b.is_null() ? 0.0 : 180.0;
  double dot = 0, na = 0, nb = 0;
  for (int i = 0; i < 3; ++i) {
    const double x = a.at(i).get<double>(), y = b.at(i).get<double>();
    dot += x * y, na += x * x, nb += y * y;
  }
  const double c = dot / std::sqrt(na * nb);
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180 / M_PI;
}

struct Diff {
  std::vector<std::string> items;
  std::size_t count = 0;
  void add(const std::string& what) {
    if (items.size() < 50) items.push_back(what);
    ++count;
  }
};

// Walks two frame records: numbers under a "dir"/"used_gaze" key by angle, pose numbers by
// absolute difference, everything else exactly.
void compare(const nlohmann::json& a, const nlohmann::json& b, const std::string& where, bool direction, double gaze_tol,
             double pose_tol, Diff& d) {
  if (direction && (a.is_array() || a.is_null() || b.is_array() || b.is_null())) {
    try {
      if (const double ang = angle(a, b); ang > gaze_tol) d.add(where + ": directions differ by " + std::to_string(ang) + " deg");
    } catch (const nlohmann::json::exception&) {
      d.add(where + ": not a direction");
    }
    return;
  }
  if (a.type() != b.type() && !(a.is_number() && b.is_number())) {
    d.add(where + ": " + a.dump() + " vs " + b.dump());
    return;
  }
  if (a.is_object()) {
    for (auto it = a.begin(); it != a.end(); ++it) {
      if (!b.contains(it.key())) {
        d.add(where + "." + it.key() + ": only in A");
        continue;
      }
      const bool dir = direction || it.key() == "dir" || it.key() == "used_gaze";
      compare(it.value(), b[it.key()], where + "." + it.key(), dir, gaze_tol, pose_tol, d);
    }
    for (auto it = b.begin(); it != b.end(); ++it)
      if (!a.contains(it.key())) d.add(where + "." + it.key() + ": only in B");
  } else if (a.is_array()) {
    if (a.size() != b.size()) {
      d.add(where + ": " + std::to_string(a.size()) + " vs " + std::to_string(b.size()) + " entries");
      return;
    }
    for (std::size_t i = 0; i < a.size(); ++i)
      compare(a[i], b[i], where + "[" + std::to_string(i) + "]", direction, gaze_tol, pose_tol, d);
  } else if (a.is_number_float() || b.is_number_float()) {
    const bool pose = where.find("eye_poses") != std::string::npos;
    const double x = a.get<double>(), y = b.get<double>();
    if (std::abs(x - y) > (pose ? pose_tol : 0.0)) d.add(where + ": " + a.dump() + " vs " + b.dump());
  } else if (a != b) {
    d.add(where + ": " + a.dump() + " vs " + b.dump());
  }
}

int run(std::vector<std::string> argv) {
  for (const auto& s : argv)
    if (s == "--help" || s == "-h") {
      std::cout << kHelp;
      return 0;
    }
  const Args args(argv, {"gaze-tol-deg", "pose-tol", "psnr-min"}, {"json"}, 2);
  if (args.positional().size() != 2) throw core::InputError("replay-diff needs two render output directories A and B (see --help)");
  const double gaze_tol = args.num("gaze-tol-deg", 1e-6), pose_tol = args.num("pose-tol", 1e-9), psnr_min = args.num("psnr-min", 60);
  if (!(gaze_tol >= 0) || !(pose_tol >= 0) || !std::isfinite(psnr_min))
    throw core::InputError("replay-diff: tolerances must be non-negative numbers");
  const fs::path A = args.positional()[0], B = args.positional()[1];
  for (const fs::path& p : {A, B})
    if (!fs::is_directory(p)) throw core::InputError(p.string() + ": not a directory");
  const auto fa = read_frames(A), fb = read_frames(B);
  Diff d;
  if (fa.size() != fb.size()) d.add("frames.jsonl: " + std::to_string(fa.size()) + " vs " + std::to_string(fb.size()) + " frames");
  for (std::size_t i = 0; i < std::min(fa.size(), fb.size()); ++i)
    compare(fa[i], fb[i], "frame " + std::to_string(i), false, gaze_tol, pose_tol, d);
  // Images: every PNG of either run.
  std::vector<std::string> names;
  for (const fs::path& dir : {A, B})
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".png") names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  nlohmann::json images = nlohmann::json::array();
  for (const std::string& n : names) {
    if (!fs::exists(A / n) || !fs::exists(B / n)) {
      d.add(n + ": only in " + (fs::exists(A / n) ? "A" : "B"));
      continue;
    }
    const core::Image ia = core::read_png((A / n).string()), ib = core::read_png((B / n).string());
    if (ia.width != ib.width || ia.height != ib.height) {
      d.add(n + ": sizes differ");
      continue;
    }
    const double p = core::psnr(ia, ib);
    images.push_back({{"image", n}, {"psnr", std::isfinite(p) ? p : 1e9}});
    if (p < psnr_min) d.add(n + ": PSNR " + std::to_string(p) + " dB < " + std::to_string(psnr_min));
  }
  if (args.has("json")) {
    std::cout << nlohmann::json({{"equal", d.count == 0},
                                 {"differences", d.count},
                                 {"first_differences", d.items},
                                 {"frames", fa.size()},
                                 {"images", images}})
                     .dump(2)
              << "\n";
  } else {
    for (const auto& s : d.items) std::cout << s << "\n";
    std::cout << (d.count == 0 ? "equal" : std::to_string(d.count) + " differences") << " (" << fa.size() << " frames, "
              << images.size() << " images compared)\n";
  }
  return d.count == 0 ? 0 : 1;
}

}  // namespace

FOVEA_COMMAND(replay_diff_command, "replay-diff", "compare two render outputs (gaze per frame, images) with tolerances", run);

}  // namespace fovea::tools::cmd_replay_diff
