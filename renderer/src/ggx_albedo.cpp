#include "ggx_albedo.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/common.hpp>
#include <glm/vec2.hpp>

#include "fovea/shaders/pt_scene.h"

namespace fovea::renderer {

namespace {

constexpr int kN = int(shaders::kPtGgxTableSize);
// Visible-normal samples per entry, on a Fibonacci lattice: every sample has its own radius
// on the sampling disk, so the horizon cut (where the energy goes) is resolved to 1/kSamples
// rather than to one ring of a square grid (which left visible steps in E over α).
constexpr int kSamples = 512;

double lambda(double cos_t, double a2) {  // Smith Λ, as pt_ggx_lambda (Heitz 2014, Eq. 72)
  const double c2 = cos_t * cos_t;
  return 0.5 * (std::sqrt(1.0 + a2 * (1.0 - c2) / std::max(c2, 1e-12)) - 1.0);
}

// (A, B) for one (μ, α): the estimator of ∫ F·D·G2/(4μ) dωi under visible-normal sampling
// (pdf G1·D/(4μ)) is F·G2/G1 (Heitz 2018); F = F0·(1 − w) + w with w = (1 − ωo·h)⁵.
glm::dvec2 albedo_ab(double mu, double alpha) {
  const double a2 = alpha * alpha, pi = std::numbers::pi;
  const double sin_o = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  // Stretched view direction in the local frame (ωo in the x-z plane).
  const double sx = alpha * sin_o, sz = mu, sl = std::sqrt(sx * sx + sz * sz);
  const double vx = sx / sl, vz = sz / sl;
  const double lo = lambda(mu, a2), g1 = 1.0 / (1.0 + lo);
  glm::dvec2 sum(0.0);
  for (int i = 0; i < kSamples; ++i) {
    const double u1 = (i + 0.5) / kSamples, u2 = std::fmod(i * 0.6180339887498949, 1.0);
    // Heitz 2018, Listing: T1 = (−vy, vx, 0)/|.| = (0, 1, 0) here, T2 = vh × T1.
    const double r = std::sqrt(u1), phi = 2.0 * pi * u2;
    const double t1 = r * std::cos(phi), s = 0.5 * (1.0 + vz);
    const double t2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - t1 * t1)) + s * r * std::sin(phi);
    const double t3 = std::sqrt(std::max(0.0, 1.0 - t1 * t1 - t2 * t2));
    // nh = t1·T1 + t2·T2 + t3·vh with T1 = (0,1,0), T2 = (−vz, 0, vx).
    const double nx = -t2 * vz + t3 * vx, ny = t1, nz = t2 * vx + t3 * vz;
    double hx = alpha * nx, hy = alpha * ny, hz = std::max(0.0, nz);
    const double hl = std::sqrt(hx * hx + hy * hy + hz * hz);
    if (!(hl > 0.0)) continue;
    hx /= hl, hy /= hl, hz /= hl;
    const double voh = sin_o * hx + mu * hz;
    const double ci = 2.0 * voh * hz - mu;  // n·reflect(−ωo, h)
    if (ci <= 0.0 || voh <= 0.0) continue;
    const double g2 = 1.0 / (1.0 + lo + lambda(ci, a2));
    const double m = std::clamp(1.0 - voh, 0.0, 1.0), w = m * m * m * m * m;
    sum += glm::dvec2(1.0 - w, w) * (g2 / g1);
  }
  return sum / double(kSamples);
}

std::vector<glm::vec4> build() {
  std::vector<glm::vec4> t(std::size_t(kN) * kN);
  for (int j = 0; j < kN; ++j) {
    const double r = double(j) / (kN - 1), alpha = std::max(r * r, 4e-4);  // pt_sampling.h's floor
    std::vector<glm::dvec2> e(kN);
    for (int i = 0; i < kN; ++i) {
      const double x = double(i) / (kN - 1);
      e[i] = albedo_ab(std::max(x * x, 1e-4), alpha);  // nodes at √μ = i/(N−1): dense at grazing
    }
    // E_avg of the piecewise-linear interpolant the shader reads, so that the layered
    // diffuse lobe's normalisation 1 − E_avg matches what it integrates (midpoint rule).
    constexpr int kSteps = 4096;
    glm::dvec2 avg(0.0);
    for (int k = 0; k < kSteps; ++k) {
      const double mu = (k + 0.5) / kSteps, x = std::sqrt(mu) * (kN - 1);
      const int i0 = std::min(int(x), kN - 2);
      avg += glm::mix(e[i0], e[i0 + 1], x - i0) * (2.0 * mu / kSteps);
    }
    for (int i = 0; i < kN; ++i)
      t[std::size_t(j) * kN + i] = glm::vec4(float(e[i].x), float(e[i].y), float(avg.x), float(avg.y));
  }
  return t;
}

}  // namespace

const std::vector<glm::vec4>& ggx_albedo_table() {
  static const std::vector<glm::vec4> table = build();
  return table;
}

}  // namespace fovea::renderer
