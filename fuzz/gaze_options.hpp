#pragma once
// Shared by the gaze harnesses: one SourceOptions (parsing the display preset once), and
// a reader drained to the end with its metadata read.
#include <string>
#include <string_view>

#include "fovea/devices/gaze.hpp"

namespace fovea::fuzz {

const devices::SourceOptions& gaze_options();
// Opens FILE as a recording (`format` forced, or "" to detect it) and reads every sample.
void drain_recording(const std::string& path, std::string_view format);

}  // namespace fovea::fuzz
