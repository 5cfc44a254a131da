#pragma once
// Display presets: a head-mounted display's per-eye raster, field of view and timing.
// Data-driven: one JSON file per preset in data/displays/ (embedded in the binaries),
// loaded by name ("fove0") or by path ("my/hmd.json"). Format: docs/file-formats.md.
#include <string>
#include <string_view>
#include <vector>

#include "fovea/core/lens_params.hpp"
#include "fovea/core/view.hpp"

namespace fovea::core {

enum class Eye { Left = 0, Right = 1 };

// What a preset may hold, checked when it is loaded (docs/file-formats.md). The raster bound
// keeps 8k-per-eye headsets and refuses rasters no stage could allocate (a 16384² eye is
// 4 GiB per RGBA32F image); the refresh and IPD bounds keep frame times and eye positions
// physical (a 1e-9 Hz display put its second frame 30 years into the gaze recording).
inline constexpr int kMaxEyePixels = 8192;          // width and height, each
inline constexpr double kMinRefreshHz = 1, kMaxRefreshHz = 1000;
inline constexpr double kMaxIpdM = 0.1;             // adults: 0.05..0.08 m
inline constexpr double kMaxCantDeg = 45;           // canted panels: 10–20° on wide headsets

struct DisplayPreset {
  std::string name;
  std::string origin;  // where it was loaded from: the preset name or the file path, for messages
  std::string description;
  int width = 0, height = 0;  // per eye, pixels
  Fov fov_left;               // the left eye's FOV; the right eye's is given or mirrored
  Fov fov_right;
  double refresh_hz = 90;
  double ipd_m = 0.063;
  // Each eye's view turned outwards about the head's up axis (canted panels, as on wide
  // headsets): binocular field = both eyes' temple half-fields + 2·cant.
  double cant_deg = 0;
  LensParams lens;   // the "lens" section (left eye; the right eye mirrors it), lens.hpp
  std::string json;  // the preset's source text, for modules that read their own sections

  const Fov& fov(Eye e) const { return e == Eye::Left ? fov_left : fov_right; }
  View view(Eye e, const Pose& pose = {}) const { return View(fov(e), width, height, pose); }
};

// The preset every entry point takes when none is given (--display, FOVEA_DISPLAY): small
// enough for the embedded CPU device's frame rate.
inline constexpr const char* kDefaultDisplay = "small";

// A name of an embedded preset, or a path to a JSON file. Throws InputError naming the
// input and the offending field, also for a lens that leaves (almost) no visible area.
DisplayPreset load_display(std::string_view name_or_path);
DisplayPreset parse_display(std::string_view json_text, std::string_view origin);
std::vector<std::string> display_preset_names();

Eye parse_eye(std::string_view s);  // "left" | "right", else InputError
const char* eye_name(Eye e);

}  // namespace fovea::core
