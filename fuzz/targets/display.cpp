// Display presets (JSON): raster, fields of view, refresh, IPD and the lens section.
#include "../harness.hpp"
#include "fovea/core/display.hpp"

FOVEA_FUZZ_TARGET(display) { (void)fovea::core::parse_display(fovea::fuzz::as_text(data), "fuzz-display.json"); }
