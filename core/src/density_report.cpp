#include "fovea/core/density_report.hpp"

#include <algorithm>
#include <cmath>

#include "fovea/core/acuity.hpp"

namespace fovea::core {
namespace {

// Every row_stride-th row's cells, each classified by its centre's flags and counted
// row_stride times; `traced(col, row)` is called for each traced one.
template <class Traced>
CellCounts visit_cells(const SampleDistribution& d, int row_stride, Traced&& traced) {
  CellCounts c;
  row_stride = std::max(row_stride, 1);
  for (int row = row_stride / 2; row < d.rows(); row += row_stride)
    for (int col = 0; col < d.columns(); ++col) {
      const std::uint32_t f = d.sample_at(col, row, {0, 0}).flags;
      if (f & (shaders::kCellClipped | shaders::kCellPadding | shaders::kCellKilled)) continue;
      c.grid_samples += row_stride;
      if (f & shaders::kCellOffscreen) {
        c.offscreen += row_stride;
      } else if (f & shaders::kCellHidden) {
        c.hidden += row_stride;
      } else {
        c.traced += row_stride;
        traced(col, row);
      }
    }
  return c;
}

}  // namespace

CellCounts count_cells(const SampleDistribution& d, int row_stride) {
  return visit_cells(d, row_stride, [](int, int) {});
}

DensityReport measure_density(const SampleDistribution& d, double band_deg, int stride, int row_stride) {
  const View& v = d.view();
  const glm::dvec3 g = d.gaze();
  DensityReport r;
  r.columns = d.columns();
  r.rows = d.rows();
  stride = std::max(stride, 1);
  const double fovea = acuity::kFoveaDeg + d.params().margin_deg;

  // Band areas and targets from the display pixels (solid angle = 1 / pixel density).
  std::vector<double> area, target, pixels;
  double fovea_pixels = 0;
  for (int y = stride / 2; y < v.height(); y += stride)
    for (int x = stride / 2; x < v.width(); x += stride) {
      const glm::dvec3 dir = v.pixel_to_dir({x + 0.5, y + 0.5});
      const double e = angle_deg(dir, g);
      const size_t b = size_t(e / band_deg);
      if (b >= area.size()) {
        area.resize(b + 1, 0.0);
        target.resize(b + 1, 0.0);
        pixels.resize(b + 1, 0.0);
      }
      const double w = double(stride) * stride;
      const double sa = w / v.pixels_per_deg2(dir);
      area[b] += sa;
      target[b] += sa * d.target_density(dir);
      pixels[b] += w;
      if (e <= fovea) fovea_pixels += w;
    }

  // Each cell counts as `kSub` fractional samples spread over its extent along the columns
  // (as jitter over frames would): counting whole cells against sharp band edges would
  // measure the column quantisation, not the density.
  constexpr int kSub = 8;
  std::vector<double> counts(area.size(), 0);
  double fovea_samples = 0;
  const double rw = std::max(row_stride, 1);
  static_cast<CellCounts&>(r) = visit_cells(d, row_stride, [&](int col, int row) {
    for (int k = 0; k < kSub; ++k) {
      const shaders::GridSample q = d.sample_at(col, row, {(k + 0.5) / kSub - 0.5, 0});
      if (q.flags & (shaders::kCellOffscreen | shaders::kCellHidden)) continue;
      const double e = angle_deg(glm::dvec3(q.dir_x, q.dir_y, q.dir_z), g);
      counts[std::min(size_t(e / band_deg), counts.size() - 1)] += rw / kSub;
      if (e <= fovea) fovea_samples += rw / kSub;
    }
  });
  r.fill = double(r.grid_samples) / (double(d.columns()) * d.rows());
  r.fovea_spp = fovea_pixels > 0 ? fovea_samples / fovea_pixels : 0;
  for (size_t b = 0; b < area.size(); ++b) {
    DensityBand band;
    band.e_min = b * band_deg;
    band.e_max = (b + 1) * band_deg;
    band.solid_angle_deg2 = area[b];
    band.samples = counts[b];
    if (area[b] > 0) {
      band.samples_per_deg2 = counts[b] / area[b];
      band.target_samples_per_deg2 = target[b] / area[b];
      band.display_pixels_per_deg2 = pixels[b] / area[b];
    }
    r.bands.push_back(band);
  }
  return r;
}

}  // namespace fovea::core
