#pragma once
// Durations given by users (URI keys, command-line options): one parser for all of them; and
// how measured times are printed, from a CPU device's seconds to a discrete GPU's fractions
// of a millisecond.
#include <string>
#include <string_view>

#include "fovea/core/clock.hpp"

namespace fovea::core {

// "20ms", "500us", "1.5ms", "250000ns", "0.02s"; a bare number is milliseconds ("20" = 20 ms).
// Non-negative and finite. Throws InputError naming `what` (e.g. the option) and the text.
TimeNs parse_duration_ns(std::string_view text, std::string_view what);

// The decimals that print `v` with `digits` significant digits in fixed notation: 0 from
// 10^(digits-1) up (1997, 452), then one more per decade down (45.3, 4.47, 0.0123); 0 for 0
// and non-finite values.
int significant_decimals(double v, int digits = 3);
// `v` printed so ("4.47", "1997").
std::string fixed_significant(double v, int digits = 3);

}  // namespace fovea::core
