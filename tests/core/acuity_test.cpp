#include "fovea/core/acuity.hpp"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace a = fovea::core::acuity;

TEST(Acuity, ContinuousAtFoveaEdge) {
  EXPECT_NEAR(a::m(a::kFoveaDeg), 1.0, 1e-12);
  EXPECT_NEAR(a::m(a::kFoveaDeg + 1e-9), 1.0, 2e-3);  // Reddy's constants meet to 0.1%
  EXPECT_NEAR(a::h(a::kFoveaDeg + 1e-9), a::h(a::kFoveaDeg), 1e-6);
  EXPECT_DOUBLE_EQ(a::m(std::nan("")), 1.0);
}

TEST(Acuity, CdfIsIntegralOfRadialPdf) {
  // h' = 2π e m(e) (P4 Eq. 2) — check by central differences across both branches.
  for (double x : {0.5, 3.0, 5.0, 7.0, 20.0, 45.0, 79.0}) {
    const double dx = 1e-5;
    const double num = (a::h(x + dx) - a::h(x - dx)) / (2 * dx);
    EXPECT_NEAR(num, 2 * std::numbers::pi * x * a::m(x), 1e-5 * num) << x;
  }
  EXPECT_NEAR(a::h(80.0), 1091.8, 0.5);  // G(80), the normaliser of the truncated CDF
}

TEST(Acuity, ExactInverseRoundTrips) {
  for (double x = 0; x <= 170; x += 0.37) EXPECT_NEAR(a::h_inverse(a::h(x)), x, 1e-9 * (1 + x)) << x;
  for (double u = 0; u <= 1; u += 0.01) EXPECT_NEAR(a::cdf(a::cdf_inverse(u)), u, 1e-12) << u;
}

TEST(Acuity, P4PolynomialApproximatesExactInverse) {
  // The paper's fit: within ~1° of the exact inverse over [0, 1], meeting at 5.79° and ~80°.
  EXPECT_NEAR(a::cdf_inverse_p4(a::kP4Branch), 5.79, 0.01);
  EXPECT_NEAR(a::cdf_inverse_p4(1.0), 80.0, 0.05);
  for (double u = 0; u <= 1; u += 0.01) EXPECT_NEAR(a::cdf_inverse_p4(u), a::cdf_inverse(u), 1.5) << u;
  for (double x = 0.1; x < 79.9; x += 0.5) EXPECT_NEAR(a::cdf_inverse_p4(a::cdf_p4(x)), x, 0.01) << x;
}

TEST(Acuity, LambertW) {
  for (double x : {-0.3678, -0.2, -0.01, 0.0, 0.5, 1.0, 10.0, 1e6}) {
    const double w = a::lambert_w0(x);
    EXPECT_NEAR(w * std::exp(w), x, 1e-10 * (1 + std::abs(x))) << x;
  }
  EXPECT_TRUE(std::isnan(a::lambert_w0(-1.0)));
}
