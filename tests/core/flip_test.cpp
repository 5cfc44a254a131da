// LDR-/HDR-FLIP against values derived by hand from the papers' formulas and published
// CIELab coordinates of the sRGB primaries (D65), not from the implementation.
#include "fovea/core/flip.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/core/tonemap.hpp"

namespace core = fovea::core;

namespace {

core::Image flat(glm::vec3 c, int w = 24, int h = 20) { return core::Image(w, h, glm::vec4(c, 1)); }

double mean(const std::vector<float>& v) {
  double s = 0;
  for (float x : v) s += x;
  return s / double(v.size());
}

// Hand pipeline: Hunt adjustment (L, 0.01·L·a, 0.01·L·b), HyAB, then q_c = 0.7 compression
// and the two-segment redistribution with p_c = 0.4, p_t = 0.95 (Andersson et al. 2020).
glm::dvec3 hunt(double l, double a, double b) { return {l, 0.01 * l * a, 0.01 * l * b}; }
double hyab(glm::dvec3 x, glm::dvec3 y) { return std::abs(x.x - y.x) + std::hypot(x.y - y.y, x.z - y.z); }
double redistribute(double d) {
  const double cmax = std::pow(hyab(hunt(87.7347, -86.1827, 83.1793), hunt(32.2970, 79.1875, -107.8602)), 0.7);
  const double c = std::pow(d, 0.7);
  return c < 0.4 * cmax ? 0.95 / (0.4 * cmax) * c : 0.95 + (c - 0.4 * cmax) / (0.6 * cmax) * 0.05;
}

}  // namespace

TEST(Flip, IdenticalImagesScoreZero) {
  core::Image a(20, 16);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) a.at(x, y) = {0.05f * x, 0.03f * y, (x * y) % 7 / 7.0f, 1};
  for (float e : core::ldr_flip(a, a)) EXPECT_EQ(e, 0.0f);
  for (float e : core::hdr_flip(a, a).error) EXPECT_EQ(e, 0.0f);
}

TEST(Flip, GreenAgainstBlueIsTheMaximumError) {
  // The redistribution maps HyAB(green, blue), the largest in the sRGB gamut, to exactly 1.
  for (float e : core::ldr_flip(flat({0, 1, 0}), flat({0, 0, 1}))) EXPECT_NEAR(e, 1.0f, 1e-5f);
}

TEST(Flip, HandComputedColourPairs) {
  // Black vs white: HyAB = ΔL = 100.
  const double bw = redistribute(100.0);
  for (float e : core::ldr_flip(flat({0, 0, 0}), flat({1, 1, 1}))) EXPECT_NEAR(e, bw, 2e-4);
  // Linear grey 0.5 (L = 116·∛0.5 − 16) vs red (53.2408, 80.0925, 67.2032): upper segment.
  const double grey_l = 116.0 * std::cbrt(0.5) - 16.0;
  const double d_red = hyab(hunt(grey_l, 0, 0), hunt(53.2408, 80.0925, 67.2032));
  EXPECT_NEAR(d_red, 78.49, 0.01);
  EXPECT_NEAR(core::flip_hyab(core::flip_hunt_lab({0.5, 0.5, 0.5}), core::flip_hunt_lab({1, 0, 0})), d_red, 0.01);
  for (float e : core::ldr_flip(flat({0.5f, 0.5f, 0.5f}), flat({1, 0, 0}))) EXPECT_NEAR(e, redistribute(d_red), 2e-4);
  // Greys 0.5 vs 0.6: ΔL only, lower (linear) segment.
  const double d_grey = 116.0 * (std::cbrt(0.6) - std::cbrt(0.5));
  EXPECT_LT(std::pow(d_grey, 0.7), 0.4 * std::pow(203.3, 0.7));
  for (float e : core::ldr_flip(flat({0.5f, 0.5f, 0.5f}), flat({0.6f, 0.6f, 0.6f})))
    EXPECT_NEAR(e, redistribute(d_grey), 2e-4);
}

TEST(Flip, SymmetricAndMonotoneInErrorMagnitude) {
  core::Image a(32, 24), b = a;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      a.at(x, y) = {((x / 4 + y / 4) & 1) ? 0.8f : 0.2f, 0.4f, 0.1f * (x % 5), 1};
      b.at(x, y) = a.at(x, y) + glm::vec4(0.1f * ((x * 7 + y * 3) % 5 - 2) / 2.0f, 0.05f, -0.02f, 0);
    }
  const std::vector<float> ab = core::ldr_flip(a, b), ba = core::ldr_flip(b, a);
  for (std::size_t i = 0; i < ab.size(); ++i) EXPECT_NEAR(ab[i], ba[i], 1e-6f);
  double previous = 0;
  for (const float d : {0.01f, 0.03f, 0.1f, 0.3f}) {
    core::Image t = a;
    for (auto& p : t.pixels) p += glm::vec4(d, d, d, 0);
    const double m = mean(core::ldr_flip(t, a));
    EXPECT_GT(m, previous) << d;
    previous = m;
  }
}

TEST(Flip, ThinDetailErrorStaysWithinTheFilters) {
  // A one-pixel line at 67 ppd: error on and next to it (CSF radius 10 px, feature σ 2.7 px),
  // none beyond both filters' reach.
  core::Image ref = flat({0.3f, 0.3f, 0.3f}, 40, 40), test = ref;
  for (int y = 0; y < 40; ++y) test.at(20, y) = {0.6f, 0.6f, 0.6f, 1};
  const std::vector<float> e = core::ldr_flip(test, ref, 67.0);
  const float on_line = e[20 * 40 + 20];
  EXPECT_GT(on_line, 0.0f);
  EXPECT_LT(on_line, 1.0f);
  EXPECT_GT(e[20 * 40 + 23], 0.0f);
  EXPECT_EQ(e[20 * 40 + 5], 0.0f);
}

TEST(Flip, HdrExposureRangeFollowsThePaper) {
  // Reference luminances: max 4 (one pixel), median 0.25: c = log2(x / Y) with t(x) = 0.85.
  core::Image ref = flat({0.25f, 0.25f, 0.25f}, 9, 9);
  ref.at(4, 4) = {4, 4, 4, 1};
  using K = core::AcesCoefficients;
  const double qa = 0.85 * K::k3 - K::k0, qb = 0.85 * K::k4 - K::k1, qc = 0.85 * K::k5 - K::k2;
  const double x = (-qb - std::sqrt(qb * qb - 4 * qa * qc)) / (2 * qa);  // qa < 0: the positive root
  EXPECT_NEAR(core::aces(x), 0.85, 1e-9);
  EXPECT_NEAR(core::aces_inverse(0.85), x, 1e-9);
  const core::HdrFlip h = core::hdr_flip_exposures(ref);
  EXPECT_NEAR(h.start_exposure, std::log2(x / 4.0), 1e-6);
  EXPECT_NEAR(h.stop_exposure, std::log2(x / 0.25), 1e-6);
  EXPECT_EQ(h.exposures, 4);  // max(2, ⌈4⌉)
}

TEST(Flip, HdrIsScaleInvariantAndBoundsEachExposure) {
  core::Image ref(24, 20), test = ref;
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) {
      ref.at(x, y) = {0.02f * x, 0.5f, x == 12 && y == 10 ? 20.0f : 0.1f, 1};
      test.at(x, y) = ref.at(x, y) * glm::vec4(1.0f + 0.3f * ((x + y) % 3 - 1), 1, 1, 1);
    }
  const core::HdrFlip h = core::hdr_flip(test, ref);
  ASSERT_GE(h.exposures, 2);
  core::Image ref8 = ref, test8 = test;
  for (auto& p : ref8.pixels) p *= glm::vec4(8, 8, 8, 1);
  for (auto& p : test8.pixels) p *= glm::vec4(8, 8, 8, 1);
  const core::HdrFlip h8 = core::hdr_flip(test8, ref8);
  EXPECT_NEAR(h8.start_exposure, h.start_exposure - 3.0, 1e-6);
  for (std::size_t i = 0; i < h.error.size(); ++i) EXPECT_NEAR(h8.error[i], h.error[i], 1e-4f);
  const std::vector<float> at_start =
      core::ldr_flip(core::tonemap_linear(test, h.start_exposure), core::tonemap_linear(ref, h.start_exposure));
  for (std::size_t i = 0; i < at_start.size(); ++i) EXPECT_GE(h.error[i], at_start[i]);
}

TEST(Flip, RejectsBadInput) {
  EXPECT_THROW(core::ldr_flip(flat({0, 0, 0}, 4, 4), flat({0, 0, 0}, 4, 5)), core::InputError);
  EXPECT_THROW(core::ldr_flip(flat({0, 0, 0}), flat({0, 0, 0}), 0.0), core::InputError);
  core::Image nan = flat({0.5f, 0.5f, 0.5f});
  nan.at(3, 3) = {NAN, INFINITY, -1, 1};
  for (float e : core::hdr_flip(nan, flat({0.5f, 0.5f, 0.5f})).error) EXPECT_TRUE(std::isfinite(e));
}
