#pragma once
// Durations given by users (URI keys, command-line options): one parser for all of them.
#include <string_view>

#include "fovea/core/clock.hpp"

namespace fovea::core {

// "20ms", "500us", "1.5ms", "250000ns", "0.02s"; a bare number is milliseconds ("20" = 20 ms).
// Non-negative and finite. Throws InputError naming `what` (e.g. the option) and the text.
TimeNs parse_duration_ns(std::string_view text, std::string_view what);

}  // namespace fovea::core
