#pragma once
// Test and benchmark access to the angular Visual-Polar σ0 solve.
#include "fovea/core/distribution.hpp"

namespace fovea::core {

// Re-solves σ0 for the current and later frames with the reference solver — 56 bisection
// steps in log σ0, each marching the column table — instead of the warm-started
// safeguarded secant, and rebuilds the frame. Tests compare the two grids;
// bench/grid_bench.cpp times both. std::invalid_argument for other distributions.
void set_reference_sigma0_solve(SampleDistribution& d, bool on);

}  // namespace fovea::core
