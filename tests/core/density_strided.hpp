#pragma once
// Shared by the Visual-Polar test files: the density measured with strides that keep the
// large presets quick (bands still hold thousands of samples).
#include <algorithm>
#include <numbers>

#include "fovea/core/density_report.hpp"
#include "fovea/core/distribution.hpp"

namespace fovea::core::test {

inline constexpr double kDeg = std::numbers::pi / 180;

inline DensityReport measure_strided(const SampleDistribution& d) {
  return measure_density(d, 2.0, std::max(1, d.view().width() / 320), std::max(1, d.rows() / 360));
}

// Its cell counts alone, for the tests that count traced cells.
inline CellCounts count_strided(const SampleDistribution& d) { return count_cells(d, std::max(1, d.rows() / 360)); }

}  // namespace fovea::core::test
