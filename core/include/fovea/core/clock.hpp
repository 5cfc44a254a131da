#pragma once
// Time in Fovea: int64 nanoseconds from a monotonic clock, everywhere.
#include <cstdint>

namespace fovea::core {

using TimeNs = std::int64_t;

// CLOCK_MONOTONIC in nanoseconds.
TimeNs now_ns();

// CPU time of the whole process (CLOCK_PROCESS_CPUTIME_ID: every thread, lavapipe's
// workers included), nanoseconds: work done on a shared machine, which its other load
// inflates far less than elapsed time. For durations only; not a timestamp.
TimeNs process_cpu_ns();

constexpr TimeNs ms_to_ns(double ms) { return static_cast<TimeNs>(ms * 1e6); }
constexpr double ns_to_ms(TimeNs ns) { return static_cast<double>(ns) * 1e-6; }

}  // namespace fovea::core
