#pragma once
// Visual acuity (Reddy 1997/2001) and the radial sampling CDF built from it
// (Koskela et al. 2018, "Instantaneous foveated preview", P4 Eq. 1–7).
// Eccentricities e, x in degrees.

namespace fovea::core::acuity {

constexpr double kFoveaDeg = 5.79;   // m(e) = 1 up to here
constexpr double kTruncDeg = 80.0;   // P4 truncates the CDF at 80°

// Normalised acuity m(e): 1 for e <= 5.79, 7.49 / (0.3e + 1)² beyond (P4 Eq. 1).
double m(double e);
// Unnormalised CDF h(x) = ∫0^x 2πe·m(e) de (P4 Eq. 5): πx² in the fovea, then
// (1/(0.3x+1) + ln(0.3x+1))·(14.98π/0.09) − C, C fixed by continuity at 5.79.
double h(double x);
// Exact inverse of h on [0, ∞) via the Lambert W function (principal branch).
double h_inverse(double y);
// f(x) = h(x)/h(80): the CDF normalised over [0, 80°], and its exact inverse.
double cdf(double x);
double cdf_inverse(double u);
// P4 Eq. 7 least-squares fit of cdf_inverse (the paper-compatible mode):
// 18.64·√u for u <= 0.0965, else 25.09u⁴ + 0.1680u³ + 27.61u² + 23.87u + 3.232.
double cdf_inverse_p4(double u);
// Exact inverse of cdf_inverse_p4 (monotone on [0, 1]); for round trips in that mode.
double cdf_p4(double x);
constexpr double kP4Branch = 0.0965;

// Lambert W0 on [-1/e, ∞).
double lambert_w0(double x);

}  // namespace fovea::core::acuity
