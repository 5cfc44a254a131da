#include "fovea/core/metrics.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/flip.hpp"
#include "fovea/core/tonemap.hpp"

namespace core = fovea::core;

namespace {

core::Image noisy(const core::Image& base, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, float(sigma));
  core::Image out = base;
  for (auto& p : out.pixels) p += glm::vec4(n(rng), n(rng), n(rng), 0);
  return out;
}

core::Image gradient(int w, int h) {
  core::Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at(x, y) = {float(x) / w, float(y) / h, 0.5f, 1};
  return img;
}

}  // namespace

TEST(Metrics, PsnrOfKnownError) {
  core::Image a(16, 8, {0.5f, 0.5f, 0.5f, 1}), b(16, 8, {0.6f, 0.6f, 0.6f, 1});
  EXPECT_NEAR(core::psnr(a, b), 20.0, 1e-4);  // MSE 0.01, peak 1
  EXPECT_EQ(core::psnr(a, a), core::kPsnrIdentical);
  // HDR values keep their full error (no clamping): an error of 10 is −20 dB.
  core::Image c(16, 8, {10.5f, 10.5f, 10.5f, 1});
  EXPECT_NEAR(core::psnr(a, c), -20.0, 1e-4);
}

TEST(Metrics, NonFiniteValuesNeverPropagate) {
  core::Image a(8, 8, {0.5f, 0.5f, 0.5f, 1}), b = a;
  b.at(3, 3) = {NAN, INFINITY, -INFINITY, 1};
  EXPECT_TRUE(std::isfinite(core::psnr(a, b)));
  EXPECT_TRUE(std::isfinite(core::ssim(a, b)));
  EXPECT_TRUE(std::isfinite(core::temporal_error(a, b)));
}

TEST(Metrics, RejectsMismatchedSizes) {
  core::Image a(8, 8), b(8, 9);
  EXPECT_THROW(core::psnr(a, b), core::InputError);
  EXPECT_THROW(core::ssim(a, b), core::InputError);
  EXPECT_THROW(core::temporal_error(a, b), core::InputError);
}

TEST(Metrics, SsimIsOneForIdenticalAndFallsWithNoise) {
  const core::Image a = gradient(48, 40);
  EXPECT_NEAR(core::ssim(a, a), 1.0, 1e-9);
  const double s1 = core::ssim(a, noisy(a, 0.02, 1)), s2 = core::ssim(a, noisy(a, 0.1, 1));
  EXPECT_LT(s1, 1.0);
  EXPECT_LT(s2, s1);
  EXPECT_GT(s2, 0.0);
  EXPECT_NEAR(core::ssim(a, noisy(a, 0.05, 2)), core::ssim(noisy(a, 0.05, 2), a), 1e-9);  // symmetric
}

TEST(Metrics, TemporalErrorIsMeanLuminanceDifference) {
  core::Image a(10, 10, {0.2f, 0.2f, 0.2f, 1}), b(10, 10, {0.5f, 0.2f, 0.2f, 1});
  EXPECT_NEAR(core::temporal_error(a, b), 0.2126 * 0.3, 1e-6);
  EXPECT_EQ(core::temporal_error(a, a), 0.0);
}

TEST(Metrics, BandsSeparateErrorsByEccentricity) {
  const core::DisplayPreset d = core::load_display("tiny");
  const core::View v = d.view(core::Eye::Left);
  const glm::dvec3 gaze = v.centre_dir();
  const std::vector<float> ecc = core::eccentricity_map(v, gaze);
  core::Image a(v.width(), v.height(), {0.3f, 0.3f, 0.3f, 1}), b = a;
  for (std::size_t i = 0; i < ecc.size(); ++i)
    if (ecc[i] >= 20) b.pixels[i] += glm::vec4(0.1f, 0.1f, 0.1f, 0);
  const auto bands = core::band_psnr(a, b, ecc, 2.0);
  ASSERT_GT(bands.size(), 12u);
  long pixels = 0;
  for (const auto& band : bands) {
    pixels += band.pixels;
    EXPECT_NEAR(band.e_max - band.e_min, 2.0, 1e-12);
    if (band.e_max <= 20) {
      EXPECT_EQ(band.psnr, core::kPsnrIdentical) << band.e_min;
    }
    if (band.e_min >= 20) {
      EXPECT_NEAR(band.psnr, 20.0, 1e-3) << band.e_min;
    }
  }
  EXPECT_EQ(pixels, long(ecc.size()));
  EXPECT_EQ(core::fovea_psnr(a, b, ecc), core::kPsnrIdentical);
  EXPECT_LT(core::psnr(a, b), 30.0);
}

TEST(Metrics, AcuitySigmaFollowsReddy) {
  // Fovea: V = 60 cpd. At 30°: m = 7.49 / (0.3·30 + 1)² = 0.0749.
  EXPECT_NEAR(core::acuity_sigma_deg(0), std::sqrt(std::log(2.0) / 2) / (M_PI * 60), 1e-12);
  EXPECT_NEAR(core::acuity_sigma_deg(30), std::sqrt(std::log(2.0) / 2) / (M_PI * 60 * 0.0749), 1e-9);
  EXPECT_LT(core::acuity_sigma_deg(10), core::acuity_sigma_deg(40));
}

TEST(Metrics, VariableGaussianKeepsConstantsAndSmoothsNoise) {
  core::Image flat(20, 12, {0.7f, 0.1f, 2.0f, 1});
  std::vector<float> sigma(flat.pixels.size(), 3.0f);
  const core::Image f = core::variable_gaussian(flat, sigma);
  for (const auto& p : f.pixels) EXPECT_NEAR(p.z, 2.0f, 1e-5f);
  const core::Image n = noisy(flat, 0.2, 3);
  EXPECT_GT(core::psnr(flat, core::variable_gaussian(n, sigma)), core::psnr(flat, n) + 8.0);
}

TEST(Metrics, FoveatedPsnrForgivesPeripheralDetailOnly) {
  const core::View v = core::load_display("small").view(core::Eye::Left);
  const glm::dvec3 gaze = v.centre_dir();
  const std::vector<float> ecc = core::eccentricity_map(v, gaze);
  core::Image ref(v.width(), v.height(), {0.4f, 0.4f, 0.4f, 1});
  // Pixel-scale checkerboard error: invisible in the far periphery, visible in the fovea.
  core::Image periph = ref, fovea = ref;
  for (int y = 0; y < v.height(); ++y)
    for (int x = 0; x < v.width(); ++x) {
      const float s = ((x + y) & 1) ? 0.1f : -0.1f;
      const std::size_t i = std::size_t(y) * v.width() + x;
      (ecc[i] > 35 ? periph : fovea).pixels[i] += glm::vec4(s, s, s, 0);
    }
  EXPECT_GT(core::foveated_psnr(ref, periph, v, gaze), core::psnr(ref, periph) + 3.0);
  EXPECT_LT(core::foveated_psnr(ref, fovea, v, gaze), core::psnr(ref, fovea) + 0.5);
}

TEST(Metrics, ToneMapIsTheStatedAcesFit) {
  // t(1) = (0.36·2.51 + 0.6·0.03) / (0.36·2.43 + 0.6·0.59 + 0.14) = 0.9216 / 1.3688.
  EXPECT_NEAR(core::tonemap_linear(glm::vec3(1.0f)).x, 0.9216 / 1.3688, 1e-6);
  EXPECT_NEAR(core::tonemap_linear(glm::vec3(0.5f), 1.0).y, 0.9216 / 1.3688, 1e-6);  // exposure +1
  EXPECT_NEAR(core::tonemap_srgb(glm::vec3(1.0f)).z, core::srgb_encode(float(0.9216 / 1.3688)), 1e-6);
  EXPECT_EQ(core::tonemap_linear(glm::vec3(1e6f)).x, 1.0f);  // clamped
  EXPECT_EQ(core::tonemap_linear(glm::vec3(NAN, -1.0f, 0.0f)), glm::vec3(0.0f));
}

TEST(Metrics, PooledScoresOfKnownErrors) {
  core::Image ref(24, 24, {1.0f, 1.0f, 1.0f, 1}), test(24, 24, {1.1f, 1.1f, 1.1f, 1});
  const core::ErrorMaps m = core::error_maps(test, ref, 10.0);
  const core::Scores s = core::pool(m);
  const double d = core::tonemap_srgb(glm::vec3(1.1f)).x - core::tonemap_srgb(glm::vec3(1.0f)).x;
  EXPECT_NEAR(s.psnr, -10.0 * std::log10(d * d), 1e-3);
  EXPECT_NEAR(s.rel_mse, 0.01 / (1.0 + core::kRelMseEpsilon), 1e-6);
  EXPECT_NEAR(s.ssim, 1.0, 1e-3);  // a uniform offset barely changes structure
  EXPECT_GT(s.ldr_flip, 0.0);
  EXPECT_GT(s.hdr_flip, 0.0);
  const core::Scores same = core::pool(core::error_maps(ref, ref, 10.0));
  EXPECT_EQ(same.psnr, core::kPsnrIdentical);
  EXPECT_EQ(same.ldr_flip, 0.0);
  EXPECT_EQ(same.hdr_flip, 0.0);
  EXPECT_NEAR(same.ssim, 1.0, 1e-9);
}

TEST(Metrics, BandAndFoveatedScoresLocaliseError) {
  const core::View v = core::load_display("tiny").view(core::Eye::Left);
  const glm::dvec3 gaze = v.centre_dir();
  const std::vector<float> ecc = core::eccentricity_map(v, gaze);
  core::Image ref(v.width(), v.height(), {0.3f, 0.3f, 0.3f, 1}), test = ref;
  for (std::size_t i = 0; i < ecc.size(); ++i)
    if (ecc[i] >= 20) test.pixels[i] += glm::vec4(0.2f, 0.2f, 0.2f, 0);
  const core::ErrorMaps m = core::error_maps(test, ref, core::flip_ppd(v));
  const auto bands = core::band_scores(m, ecc, 2.0);
  ASSERT_GT(bands.size(), 12u);
  for (const auto& b : bands) {
    if (b.e_max <= 16) {  // beyond the FLIP/SSIM filter reach of the 20° boundary
      EXPECT_EQ(b.scores.psnr, core::kPsnrIdentical) << b.e_min;
      EXPECT_NEAR(b.scores.ldr_flip, 0.0, 1e-6) << b.e_min;
      EXPECT_NEAR(b.scores.hdr_flip, 0.0, 1e-6) << b.e_min;
    }
    if (b.e_min >= 24) {
      EXPECT_LT(b.scores.psnr, 30.0) << b.e_min;
      EXPECT_GT(b.scores.ldr_flip, 0.05) << b.e_min;
      EXPECT_GT(b.scores.rel_mse, 0.1) << b.e_min;
    }
  }
  const std::vector<float> w = core::foveation_weights(ecc);
  const core::Scores fov = core::pool(m, w), all = core::pool(m);
  EXPECT_GT(fov.psnr, all.psnr + 1.0);  // 93% of the pixels carry the error, 63% of the weight
  EXPECT_LT(fov.ldr_flip, all.ldr_flip);
  EXPECT_NEAR(core::foveation_weights({0.0f, 5.0f, 30.0f})[2], 7.49 / (10.0 * 10.0), 1e-6);
  EXPECT_EQ(core::foveation_weights({0.0f, 5.0f, 30.0f})[1], 1.0f);
}

TEST(Metrics, FlickerIsTheTemporalStdOfToneMappedLuma) {
  core::Image a(8, 8, {0.2f, 0.2f, 0.2f, 1}), b(8, 8, {0.4f, 0.4f, 0.4f, 1});
  const double ya = core::tonemap_srgb(glm::vec3(0.2f)).x, yb = core::tonemap_srgb(glm::vec3(0.4f)).x;
  for (float f : core::flicker_map({a, b, a, b})) EXPECT_NEAR(f, 0.5 * (yb - ya), 1e-6);
  for (float f : core::flicker_map({a, a, a})) EXPECT_NEAR(f, 0.0f, 1e-7f);
  EXPECT_THROW(core::flicker_map({a}), core::InputError);
  EXPECT_THROW(core::flicker_map({a, core::Image(4, 4)}), core::InputError);
}
