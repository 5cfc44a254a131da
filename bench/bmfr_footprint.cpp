// Screen footprint of BMFR's 32×32 blocks on a Visual-Polar grid (issue: blocks whose screen
// footprint stays compact). Per eccentricity band of the block's centroid, over the blocks
// of the left eye's grid at a gaze: the blocks' cell count, radial and tangential extent and
// elongation, for two block layouts:
//   rows   the shader's layout: 32 columns × 32 consecutive rows of each column (row v of
//          column x lies at φ = φ0_x + 2π (v + ½) / R_x, so where R_x changes across the
//          block's columns its rows drift apart in φ: the block shears into a spiral arm);
//   phi    the alternative: 32 columns × one φ sector of each column's arc (the full turn,
//          or a packed column's visible arc), the sector count per 32-column band
//          round(R_mid / 32) (R_mid: rows of the band's middle column), so a block covers the
//          same φ range in each of its columns (φ extent scaled with ρ).
// Extents from the cells' positions around the gaze in degrees (azimuthal equidistant:
// ρ (cos φ, sin φ), ρ the eccentricity): σ1 ≥ σ2 the principal standard deviations,
// "length" = √12 σ1 (a uniform segment's full length), "elong" = σ1 / σ2 (a square: 1),
// "pixels" the length in display pixels (same from the cells' screen positions).
// Medians over the band's blocks; cells clipped by the view or its packing are left out.
//   fovea_bmfr_footprint [display] [gaze_deg]      (defaults: fove0 0)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"

namespace fc = fovea::core;

namespace {

struct Cell {
  double ecc, phi;  // degrees, radians around the gaze
  double px, py;    // display pixels
};

struct Moments {
  double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  void add(double x, double y) { n += 1, sx += x, sy += y, sxx += x * x, syy += y * y, sxy += x * y; }
  // Principal standard deviations σ1 ≥ σ2.
  std::pair<double, double> sigmas() const {
    const double mx = sx / n, my = sy / n;
    const double a = sxx / n - mx * mx, b = sxy / n - mx * my, c = syy / n - my * my;
    const double tr = 0.5 * (a + c), det = std::sqrt(std::max(0.0, 0.25 * (a - c) * (a - c) + b * b));
    return {std::sqrt(std::max(0.0, tr + det)), std::sqrt(std::max(0.0, tr - det))};
  }
};

struct Block {
  Moments deg, pix;
  double ecc_sum = 0, ecc_min = 1e9, ecc_max = -1e9;
  void add(const Cell& c) {
    deg.add(c.ecc * std::cos(c.phi), c.ecc * std::sin(c.phi));
    pix.add(c.px, c.py);
    ecc_sum += c.ecc, ecc_min = std::min(ecc_min, c.ecc), ecc_max = std::max(ecc_max, c.ecc);
  }
};

// φ of a sample around the gaze, in the basis the grid's φ is measured from.
double phi_of(const fovea::shaders::GridSample& s, glm::dvec3 b1, glm::dvec3 b2) {
  const glm::dvec3 dir(s.dir_x, s.dir_y, s.dir_z);
  return std::atan2(glm::dot(dir, b2), glm::dot(dir, b1));
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

void report(const char* layout, const std::map<long, Block>& blocks) {
  struct Band {
    std::vector<double> cells, radial, length, elong, pixels;
  };
  static constexpr double kEdges[] = {0, 5, 10, 20, 30, 40, 60, 90};
  std::map<int, Band> bands;
  for (const auto& [key, b] : blocks) {
    if (b.deg.n < 32) continue;  // slivers at the view's edge
    const double ecc = b.ecc_sum / b.deg.n;
    int k = 0;
    while (k + 2 < int(std::size(kEdges)) && ecc >= kEdges[k + 1]) ++k;
    const auto [s1, s2] = b.deg.sigmas();
    Band& band = bands[k];
    band.cells.push_back(b.deg.n);
    band.radial.push_back(b.ecc_max - b.ecc_min);
    band.length.push_back(std::sqrt(12.0) * s1);
    band.elong.push_back(s1 / std::max(s2, 1e-9));
    band.pixels.push_back(std::sqrt(12.0) * b.pix.sigmas().first);
  }
  for (const auto& [k, b] : bands)
    std::printf("| %s | %g–%g | %zu | %.0f | %.2f | %.2f | %.2f | %.0f |\n", layout, kEdges[k], kEdges[k + 1],
                b.cells.size(), median(b.cells), median(b.radial), median(b.length), median(b.elong),
                median(b.pixels));
}

}  // namespace

int main(int argc, char** argv) {
  const std::string display = argc > 1 ? argv[1] : "fove0";
  const double gaze_deg = argc > 2 ? std::atof(argv[2]) : 0.0;
  const fc::DisplayPreset d = fc::load_display(display);
  fc::DistributionParams p;
  p.jitter = false;
  auto dist = fc::make_distribution(d.view(fc::Eye::Left), p);
  const double t = std::tan(gaze_deg * M_PI / 180);
  const glm::dvec3 gaze = glm::normalize(glm::dvec3(t, 0, -1));
  dist->set_frame(gaze);
  glm::dvec3 b1, b2;
  fc::orthonormal_basis(gaze, b1, b2);
  const auto& table = dist->column_table();
  const int columns = dist->columns();
  std::map<long, Block> rows_layout, phi_layout;
  for (int x = 0; x < columns; ++x) {
    const int band = x / 32;
    const int mid = std::min(band * 32 + 16, columns - 1);
    const int sectors = std::max(1, int(std::lround(table[std::size_t(mid)].rows / 32.0)));
    for (int v = 0; v < int(table[std::size_t(x)].rows); ++v) {
      const fovea::shaders::GridSample s = dist->sample(x, v);
      if (s.flags != 0) continue;
      const Cell c{s.ecc_deg, phi_of(s, b1, b2), s.screen_x, s.screen_y};
      rows_layout[long(band) * 100000 + v / 32].add(c);
      // Position along the column's arc in [0, 1): from φ0 over 2π − gap (a full ring: the turn).
      const auto& col = table[std::size_t(x)];
      const double arc = (std::fmod(phi_of(s, b1, b2) - col.phi0 + 4 * M_PI, 2 * M_PI)) / (2 * M_PI - col.phi_gap);
      phi_layout[long(band) * 100000 + std::clamp(int(arc * sectors), 0, sectors - 1)].add(c);
    }
  }
  std::printf("%s, gaze %g deg, %d columns; medians per band of the block's mean eccentricity\n", display.c_str(),
              gaze_deg, columns);
  std::printf("| layout | band (deg) | blocks | cells | radial span (deg) | length (deg) | elong | length (px) |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  report("rows", rows_layout);
  report("phi", phi_layout);
  return 0;
}
