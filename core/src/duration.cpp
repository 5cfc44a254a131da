#include "fovea/core/duration.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

#include "fovea/core/error.hpp"

namespace fovea::core {

TimeNs parse_duration_ns(std::string_view text, std::string_view what) {
  const auto bad = [&] {
    return InputError(std::string(what) + ": \"" + std::string(text) +
                      "\" is not a duration (a number >= 0 with unit ms, us, ns or s; a bare number is milliseconds)");
  };
  double v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || r.ec != std::errc() || !std::isfinite(v) || v < 0) throw bad();
  const std::string_view unit(r.ptr, static_cast<std::size_t>(text.data() + text.size() - r.ptr));
  double scale = 0;
  if (unit.empty() || unit == "ms") scale = 1e6;
  else if (unit == "us") scale = 1e3;
  else if (unit == "ns") scale = 1;
  else if (unit == "s") scale = 1e9;
  else throw bad();
  const double ns = v * scale;
  if (ns > 9.0e18) throw bad();  // beyond int64 nanoseconds
  return static_cast<TimeNs>(std::llround(ns));
}

int significant_decimals(double v, int digits) {
  if (!std::isfinite(v) || v == 0) return 0;
  const int decade = int(std::floor(std::log10(std::abs(v))));
  return std::clamp(digits - 1 - decade, 0, 12);
}

std::string fixed_significant(double v, int digits) {
  char b[48];
  std::snprintf(b, sizeof b, "%.*f", significant_decimals(v, digits), v);
  return b;
}

}  // namespace fovea::core
