#include "fovea/core/metrics.hpp"

#include <algorithm>
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

// The erosion behind partial-reference scoring, against a brute-force neighbourhood scan:
// a pixel is scorable when every pixel of its (2r+1)² square inside the image is valid.
TEST(Metrics, ScorablePixelsAreTheValidMaskErodedBySquares) {
  const int w = 23, h = 17;
  std::mt19937 rng(5);
  std::vector<bool> valid(std::size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) valid[std::size_t(y) * w + x] = (x - 11) * (x - 11) + (y - 8) * (y - 8) < 60 || rng() % 9 == 0;
  for (int r : {0, 1, 2, 5, 30}) {
    const std::vector<bool> s = core::scorable_pixels(valid, w, h, r);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        bool all = true;
        for (int v = std::max(0, y - r); v <= std::min(h - 1, y + r); ++v)
          for (int u = std::max(0, x - r); u <= std::min(w - 1, x + r); ++u) all = all && valid[std::size_t(v) * w + u];
        EXPECT_EQ(s[std::size_t(y) * w + x], all) << "r " << r << " at " << x << "," << y;
      }
  }
  // Every pixel valid: the image border clips the neighbourhood, nothing is lost.
  const std::vector<bool> full(std::size_t(w) * h, true);
  EXPECT_EQ(core::scorable_pixels(full, w, h, 5), full);
  EXPECT_EQ(core::scorable_pixels({true}, 1, 1, 5), std::vector<bool>{true});
  EXPECT_THROW(core::scorable_pixels(full, w + 1, h, 1), core::InputError);
  // The support: SSIM's 11×11 window at low density, FLIP's CSF filter at the paper's 67 ppd.
  EXPECT_EQ(core::error_map_support_px(10.0), core::kSsimRadius);
  EXPECT_EQ(core::error_map_support_px(67.0), core::flip_support_px(67.0));
  EXPECT_EQ(core::flip_support_px(67.0), 10);  // ⌈3·√(0.04 / 2π²)·67⌉
}

// A reference that holds only a window: wherever the window holds a pixel's whole
// neighbourhood, every error map equals the one against a reference complete everywhere
// (HDR-FLIP when both take their exposure range from the window); at the window's edge
// they differ, so the margin is needed.
TEST(Metrics, PartialReferenceGivesTheWholeReferencesMapsWhereItHoldsTheNeighbourhood) {
  const int w = 40, h = 36;
  core::Image whole = noisy(gradient(w, h), 0.2, 1);
  for (auto& p : whole.pixels) p = glm::abs(p) * 3.0f;  // HDR
  const core::Image test = noisy(whole, 0.1, 2);
  std::vector<bool> valid(whole.pixels.size());
  core::Image partial = whole;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      valid[i] = (x - 18) * (x - 18) + (y - 20) * (y - 20) <= 14 * 14;
      if (!valid[i]) partial.pixels[i] = glm::vec4(0);  // not traced
    }
  const double ppd = 30.0;
  const std::vector<bool> scorable = core::scorable_pixels(valid, w, h, core::error_map_support_px(ppd));
  const core::ErrorMaps p = core::error_maps(test, partial, ppd, 0.0, valid);
  const core::ErrorMaps f = core::error_maps(test, whole, ppd, 0.0, valid);
  const core::ErrorMaps f_own = core::error_maps(test, whole, ppd);  // exposures from every pixel
  std::size_t inside = 0, edge_differs = 0;
  for (std::size_t i = 0; i < scorable.size(); ++i) {
    if (!scorable[i]) {
      edge_differs += valid[i] && p.ssim[i] != f.ssim[i];
      continue;
    }
    ++inside;
    EXPECT_EQ(p.squared_error[i], f_own.squared_error[i]) << i;
    EXPECT_EQ(p.ssim[i], f_own.ssim[i]) << i;
    EXPECT_EQ(p.rel_mse[i], f_own.rel_mse[i]) << i;
    EXPECT_EQ(p.ldr_flip[i], f_own.ldr_flip[i]) << i;
    EXPECT_EQ(p.hdr_flip[i], f.hdr_flip[i]) << i;
  }
  EXPECT_GT(inside, 100u);
  EXPECT_GT(edge_differs, 0u);
  // The exposure range of the window's pixels is that of an image of those pixels alone.
  core::Image held(int(std::count(valid.begin(), valid.end(), true)), 1);
  for (std::size_t i = 0, k = 0; i < valid.size(); ++i)
    if (valid[i]) held.pixels[k++] = whole.pixels[i];
  const core::HdrFlip a = core::hdr_flip_exposures(partial, valid), b = core::hdr_flip_exposures(held);
  EXPECT_EQ(a.start_exposure, b.start_exposure);
  EXPECT_EQ(a.stop_exposure, b.stop_exposure);
  EXPECT_EQ(a.exposures, b.exposures);
  EXPECT_THROW(core::hdr_flip_exposures(partial, std::vector<bool>(valid.size(), false)), core::InputError);
}

// band_index is the band band_scores puts a pixel in: its [k·w, (k+1)·w) bounds hold e.
TEST(Metrics, BandIndexAgreesWithTheBandBoundsAtTheirEdges) {
  for (double w : {2.0, 0.1, 0.3, 5.0})
    for (int k = 0; k < 200; ++k)
      for (float e : {float(k * w), std::nextafter(float(k * w), 0.0f), std::nextafter(float(k * w), 1e9f)}) {
        const int b = core::band_index(e, w);
        EXPECT_GE(double(e), b * w) << "e " << e << " w " << w;
        EXPECT_LT(double(e), (b + 1) * w) << "e " << e << " w " << w;
      }
}
