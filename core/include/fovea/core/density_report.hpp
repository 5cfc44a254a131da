#pragma once
// Measured sample density of a distribution for its current frame: what `fovea density`
// reports and what the distribution tests check against the target σ(e).
#include <cstdint>
#include <vector>

#include "fovea/core/distribution.hpp"

namespace fovea::core {

struct DensityBand {
  double e_min = 0, e_max = 0;         // eccentricity band around the gaze, degrees
  double solid_angle_deg2 = 0;         // the band's solid angle inside the view
  double samples = 0;                  // traced samples in the band (cells spread over their extent)
  double samples_per_deg2 = 0;         // measured
  double target_samples_per_deg2 = 0;  // the distribution's intent, averaged over the band
  double display_pixels_per_deg2 = 0;  // average display density in the band
};

// The grid's cells by what becomes of them this frame.
struct CellCounts {
  std::int64_t grid_samples = 0;   // cells with a sample (not clipped, padded or killed)
  std::int64_t traced = 0;         // cells actually traced (also on screen and visible)
  std::int64_t offscreen = 0;
  std::int64_t hidden = 0;
};

struct DensityReport : CellCounts {
  int columns = 0, rows = 0;
  double fill = 0;                 // useful cells / (columns·rows)
  double fovea_spp = 0;            // traced samples per display pixel within e <= 5.79° + s
  std::vector<DensityBand> bands;
};

// Iterates every cell and display pixel; strides > 1 visit every n-th pixel (both axes)
// and every n-th row of the grid, weighting each visit n² resp. n times, for quick
// checks on large displays. band_deg: band width.
DensityReport measure_density(const SampleDistribution& d, double band_deg = 2.0, int pixel_stride = 1,
                              int row_stride = 1);

// measure_density's cell counts alone (each cell's centre classified once, no bands): a
// ninth of its cost on a large grid.
CellCounts count_cells(const SampleDistribution& d, int row_stride = 1);

}  // namespace fovea::core
