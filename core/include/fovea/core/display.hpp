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

struct DisplayPreset {
  std::string name;
  std::string description;
  int width = 0, height = 0;  // per eye, pixels
  Fov fov_left;               // the left eye's FOV; the right eye's is given or mirrored
  Fov fov_right;
  double refresh_hz = 90;
  double ipd_m = 0.063;
  LensParams lens;   // the "lens" section (left eye; the right eye mirrors it), lens.hpp
  std::string json;  // the preset's source text, for modules that read their own sections

  const Fov& fov(Eye e) const { return e == Eye::Left ? fov_left : fov_right; }
  View view(Eye e, const Pose& pose = {}) const { return View(fov(e), width, height, pose); }
};

// A name of an embedded preset, or a path to a JSON file. Throws InputError naming the
// input and the offending field.
DisplayPreset load_display(std::string_view name_or_path);
DisplayPreset parse_display(std::string_view json_text, std::string_view origin);
std::vector<std::string> display_preset_names();

Eye parse_eye(std::string_view s);  // "left" | "right", else InputError
const char* eye_name(Eye e);

}  // namespace fovea::core
