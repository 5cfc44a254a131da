#include "fovea/core/density_report.hpp"

#include <algorithm>
#include <cmath>

#include "fovea/core/acuity.hpp"

namespace fovea::core {

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
  row_stride = std::max(row_stride, 1);
  const double rw = row_stride;
  for (int row = row_stride / 2; row < d.rows(); row += row_stride)
    for (int col = 0; col < d.columns(); ++col) {
      const shaders::GridSample s = d.sample_at(col, row, {0, 0});
      const std::uint32_t f = s.flags;
      if (f & (shaders::kCellClipped | shaders::kCellPadding | shaders::kCellKilled)) continue;
      r.grid_samples += row_stride;
      if (f & shaders::kCellOffscreen) {
        r.offscreen += row_stride;
        continue;
      }
      if (f & shaders::kCellHidden) {
        r.hidden += row_stride;
        continue;
      }
      r.traced += row_stride;
      for (int k = 0; k < kSub; ++k) {
        const shaders::GridSample q = d.sample_at(col, row, {(k + 0.5) / kSub - 0.5, 0});
        if (q.flags & (shaders::kCellOffscreen | shaders::kCellHidden)) continue;
        const double e = angle_deg(glm::dvec3(q.dir_x, q.dir_y, q.dir_z), g);
        counts[std::min(size_t(e / band_deg), counts.size() - 1)] += rw / kSub;
        if (e <= fovea) fovea_samples += rw / kSub;
      }
    }
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
