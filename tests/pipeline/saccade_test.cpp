// History validity that knows cell size: after a 40° saccade the new fovea lands on cells
// that were peripheral (several times coarser) one frame earlier. Their history is rejected,
// and the fovea is as sharp as with a fixed gaze within 3 frames (90 Hz-equivalent count).
// Albedo detail is re-modulated from the current frame's samples (sharp whatever the
// history), so the rejection is checked directly on the fovea's history count.
#include <array>
#include <cmath>
#include <string>
#include <tuple>

#include "fovea/core/flip.hpp"
#include "fovea/core/metrics.hpp"
#include "fovea/pipeline/frame_config.hpp"
#include "fovea/renderer/reference.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

namespace {

constexpr double kDeg = M_PI / 180;
constexpr double kTarget = 20;  // the gaze jumps from -20° to +20° horizontally

// A dark wall 1.5 in front of the eye under a constant white sky, with a checkerboard of
// bright 1.5° squares within 9° of the saccade's target: a Lambert plane that sees the whole
// sky has no noise under cosine sampling, so only reconstruction changes the image.
renderer::Scene checker_wall() {
  renderer::Scene s;
  s.name = "checker-wall";
  s.environment = glm::vec3(1);
  renderer::Material dark;
  dark.base_color = glm::vec3(0.05f);
  dark.specular = 0;
  renderer::Material bright = dark;
  bright.base_color = glm::vec3(0.8f);
  const std::uint32_t md = s.add_material(dark), mb = s.add_material(bright);
  const float z = -1.5f;
  s.add_quad({-40, -40, z}, {40, -40, z}, {40, 40, z}, {-40, 40, z}, md);
  const float cx = 1.5f * float(std::tan(kTarget * kDeg)), q = 1.5f * float(std::tan(1.5 * kDeg));
  for (int j = -6; j < 6; ++j)
    for (int i = -6; i < 6; ++i) {
      if ((i + j) & 1) continue;
      const float x0 = cx + i * q, y0 = j * q, zz = z + 1e-3f;
      s.add_quad({x0, y0, zz}, {x0 + q, y0, zz}, {x0 + q, y0 + q, zz}, {x0, y0 + q, zz}, mb);
    }
  return s;
}

// Mean squared gradient of the luminance, pre-smoothed with a Gaussian of σ = 1 px (so that
// sub-pixel anti-aliasing does not count, cell-sized blur does), over the pixels within 5°
// of the gaze.
double fovea_sharpness(const core::Image& img, const core::View& v, glm::dvec3 gaze) {
  const int w = img.width, h = img.height;
  std::vector<double> lum(std::size_t(w) * h), tmp(lum.size()), sm(lum.size());
  for (int i = 0; i < w * h; ++i) {
    const glm::vec4 c = img.pixels[std::size_t(i)];
    lum[std::size_t(i)] = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
  }
  const double k[5] = {std::exp(-2.0), std::exp(-0.5), 1.0, std::exp(-0.5), std::exp(-2.0)};
  const auto blur = [&](const std::vector<double>& src, std::vector<double>& dst, int dx, int dy) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        double s = 0, ws = 0;
        for (int t = -2; t <= 2; ++t) {
          const int xx = x + t * dx, yy = y + t * dy;
          if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          s += k[t + 2] * src[std::size_t(yy) * w + xx], ws += k[t + 2];
        }
        dst[std::size_t(y) * w + x] = s / ws;
      }
  };
  blur(lum, tmp, 1, 0);
  blur(tmp, sm, 0, 1);
  double g2 = 0;
  long n = 0;
  for (int y = 0; y + 1 < h; ++y)
    for (int x = 0; x + 1 < w; ++x) {
      if (core::angle_deg(v.pixel_to_dir({x + 0.5, y + 0.5}), gaze) > 5) continue;
      const double gx = sm[std::size_t(y) * w + x + 1] - sm[std::size_t(y) * w + x];
      const double gy = sm[std::size_t(y + 1) * w + x] - sm[std::size_t(y) * w + x];
      g2 += gx * gx + gy * gy, ++n;
    }
  return n ? g2 / double(n) : 0.0;
}

// Mean Phase I sample count (direct, .w) of the traced cells within 5° of the gaze.
double fovea_history(const pipeline::FramePipeline& p) {
  const auto acc = pipeline::testing::grid_buffer(p, core::Eye::Left, pipeline::testing::GridBuffer::AccDirect);
  const auto samples = p.grid_samples(core::Eye::Left);
  double sum = 0;
  long n = 0;
  for (std::size_t i = 0; i < acc.size(); ++i)
    if (samples[i].flags == 0 && samples[i].ecc_deg <= 5) sum += acc[i].w, ++n;
  return n ? sum / double(n) : 0.0;
}

// A converged reference of the fovea, the pixels within 5° of `gaze`, at up to `spp`.
fovea::test::FoveaReference fovea_reference(fovea::gpu::Context& ctx, const renderer::GpuScene& gs,
                                            const core::View& view, glm::dvec3 gaze, std::uint32_t spp) {
  renderer::ReferenceOptions o;
  o.path.spp = 64;
  o.max_spp = spp;
  return fovea::test::fovea_reference(ctx, gs, view, gaze, o, 5.0);
}

// The recovery curves' setting: a shipped scene from its camera, 256×288 at 60°×66° (≈ 4 px/°
// at the landing point), 4 samples per cell and frame, 10 frames before the jump, 8 after.
struct CurveSetting {
  static constexpr int settle = 10, after = 8;
  renderer::Scene scene;
  core::DisplayPreset display = fovea::test::display_of_size(256, 288);
  std::array<core::Pose, 2> poses;
  glm::dvec3 target = fovea::test::horizontal_gaze(kTarget), before = fovea::test::horizontal_gaze(-kTarget);
  renderer::PathConfig path;

  explicit CurveSetting(const char* name) : scene(renderer::load_scene(name)) {
    display.fov_left = display.fov_right = core::Fov::from_degrees(-30, 30, 33, -33);
    poses = core::eye_poses(scene.camera, display);
    path.spp = 4;
  }
};

}  // namespace

TEST_F(GpuTest, FoveaIsSharpWithinThreeFramesAfterA40DegreeSaccade) {
  const renderer::Scene scene = checker_wall();
  renderer::GpuScene gs(ctx(), scene);
  // 60° wide at 256 px: ~4 px/° where the gaze lands, so the old periphery's cells (40° out)
  // are several pixels wide while the fovea's are about one.
  core::DisplayPreset display = fovea::test::display_of_size(256, 288);
  display.fov_left = display.fov_right = core::Fov::from_degrees(-30, 30, 33, -33);
  const auto poses = core::eye_poses(core::Pose{}, display);
  const glm::dvec3 target = fovea::test::horizontal_gaze(kTarget), before = fovea::test::horizontal_gaze(-kTarget);
  const int settle = 10, after = 8;
  // Without a denoiser the display shows Phase I's history directly; with BMFR (the
  // default) the TAA's neighbourhood clamp also limits what a blurred history can do.
  for (const auto denoiser : {reconstruct::Denoiser::None, reconstruct::Denoiser::Bmfr}) {
    reconstruct::ReconSettings s;
    s.denoiser = denoiser;
    pipeline::FramePipeline control(ctx(), gs, core::stereo_views(display), {}, s, {}, true);
    for (int f = 0; f < settle + after; ++f) control.render(poses, {target, target}, std::uint32_t(f));
    const double sharp = fovea_sharpness(control.image(core::Eye::Left), control.view(core::Eye::Left), target);
    EXPECT_GT(sharp, 1e-3);  // the checkerboard is there

    pipeline::FramePipeline jump(ctx(), gs, core::stereo_views(display), {}, s, {}, true);
    for (int f = 0; f < settle; ++f) jump.render(poses, {before, before}, std::uint32_t(f));
    for (int f = 0; f < after; ++f) {
      jump.render(poses, {target, target}, std::uint32_t(settle + f));
      const double r = fovea_sharpness(jump.image(core::Eye::Left), jump.view(core::Eye::Left), target) / sharp;
      std::printf("%s, frame %d after the saccade: fovea sharpness %.3f of the fixed gaze's, history %.2f samples\n",
                  reconstruct::denoiser_name(denoiser), f + 1, r, fovea_history(jump));
      // The mechanism itself: the fovea's history from 40° out is rejected at the jump (its
      // samples start over with the frame's own landing_spp; measured 5.8 frames of history
      // without the cell-size test) and accepted again from the next frame on (same-size
      // cells), each landing frame adding landing_spp samples.
      const double count = fovea_history(jump), per_frame = s.landing_spp;
      if (f == 0) {
        EXPECT_LT(count, per_frame + 0.05);
      }
      if (f == 1) {
        EXPECT_GT(count, 2 * per_frame - 0.1);
      }
      if (f >= 2) {  // from the third frame after the jump on
        EXPECT_NEAR(r, 1.0, 0.1) << f + 1;
      }
    }
  }
}

// The saccade recovery curve on the shipped `default` scene (docs/reconstruction.md): fovea
// sharpness per frame after a 40° gaze jump as a fraction of a fixed gaze's, with and without
// the cell-size test (keep/reject at 10⁹), sub-cell jitter on (the default), both denoisers.
// 4 samples per cell and frame: the measure (gradient energy) counts noise as detail, and at
// 1 spp a fovea that starts over is "sharper" than the converged control by its noise alone.
// Printed as the table's rows, with the fovea's tone-mapped PSNR and HDR-FLIP against a
// converged reference and the control's; asserts the mechanism (with the test the fovea's
// history starts over at the jump, without it the coarse history is kept) and, with the
// test, the goal for both denoisers: the fovea within 10% of the control from the third
// frame after the jump (BMFR before the restart window's 5×5 average and running mean:
// 1.129 at the third frame, within 10% only from the fifth), and with BMFR as close to the
// reference as the control from the second frame (the lower ratio is not blur).
TEST_F(GpuTest, SaccadeRecoveryCurveOnTheDefaultScene) {
  const CurveSetting c("default");
  renderer::GpuScene gs(ctx(), c.scene, {}, fovea::test::kStatisticsTracing);
  fovea::test::FoveaReference ref;
  for (const auto denoiser : {reconstruct::Denoiser::None, reconstruct::Denoiser::Bmfr}) {
    reconstruct::ReconSettings s;
    s.denoiser = denoiser;
    pipeline::FramePipeline control(ctx(), gs, core::stereo_views(c.display), {}, s, c.path, true);
    std::vector<double> sharp(c.after);
    std::vector<core::Scores> control_scores(c.after);
    for (int f = 0; f < c.settle + c.after; ++f) {
      control.render(c.poses, {c.target, c.target}, std::uint32_t(f));
      if (ref.image.pixels.empty())  // the view holds the eye's pose once a frame was rendered
        ref = fovea_reference(ctx(), gs, control.view(core::Eye::Left), c.target, 1024);
      if (f >= c.settle) {
        sharp[std::size_t(f - c.settle)] =
            fovea_sharpness(control.image(core::Eye::Left), control.view(core::Eye::Left), c.target);
        control_scores[std::size_t(f - c.settle)] = fovea::test::fovea_scores(control.image(core::Eye::Left), ref);
      }
    }
    for (const bool check : {true, false}) {
      if (!check) s.coarse_keep = s.coarse_reject = 1e9f;
      pipeline::FramePipeline jump(ctx(), gs, core::stereo_views(c.display), {}, s, c.path, true);
      for (int f = 0; f < c.settle; ++f) jump.render(c.poses, {c.before, c.before}, std::uint32_t(f));
      std::printf("%s, cell-size test %s: sharpness / control (history) per frame after the jump:",
                  reconstruct::denoiser_name(denoiser), check ? "on" : "off");
      for (int f = 0; f < c.after; ++f) {
        jump.render(c.poses, {c.target, c.target}, std::uint32_t(c.settle + f));
        const double r = fovea_sharpness(jump.image(core::Eye::Left), jump.view(core::Eye::Left), c.target) /
                         sharp[std::size_t(f)];
        const double count = fovea_history(jump);
        const core::Scores q = fovea::test::fovea_scores(jump.image(core::Eye::Left), ref);
        const core::Scores& qc = control_scores[std::size_t(f)];
        std::printf(" %.3f (%.2f) [%.2f dB %.3f | control %.2f dB %.3f]", r, count, q.psnr, q.hdr_flip, qc.psnr,
                    qc.hdr_flip);
        EXPECT_TRUE(std::isfinite(r));
        const bool none = denoiser == reconstruct::Denoiser::None;
        // Within 10% of the control's sharpness from the third frame; below 0.9 only with a
        // fovea closer to the reference than the control's (as SaccadeRecoveryPerScene): the
        // control, a still view, converges without TAA, and its remaining noise counts as
        // gradient energy (docs/reconstruction.md, "History weights").
        if (check && f >= 2) {
          EXPECT_LE(r, 1.1) << reconstruct::denoiser_name(denoiser) << ", frame " << f + 1;
          if (r < 0.9) {  // and not worse than the control (below, from the second frame)
            EXPECT_GE(q.psnr, qc.psnr - 0.5) << reconstruct::denoiser_name(denoiser) << ", frame " << f + 1;
            EXPECT_LE(q.hdr_flip, qc.hdr_flip + 0.003) << reconstruct::denoiser_name(denoiser) << ", frame " << f + 1;
          }
        }
        // Less gradient energy is less noise, not blur: from the second frame on the fovea
        // is as close to the reference as the fixed gaze's (before the restart window's
        // running mean: 4.0 dB below it at the second frame, 1.5 dB at the fourth).
        if (check && !none && f >= 1) {
          EXPECT_GE(q.psnr, qc.psnr - 0.5) << "frame " << f + 1;
          EXPECT_LE(q.hdr_flip, qc.hdr_flip + 0.003) << "frame " << f + 1;
        }
        if (f == 0) {  // Phase I counts samples: the frame's own c.path.spp after a restart
          const double own = c.path.spp;  // (a path of several samples takes no landing samples)
          if (check) {
            EXPECT_LT(count, own + 0.05);
          } else {  // the coarse history kept, for ReconSettings::landing_history samples at most
            EXPECT_GT(count, own + 0.5);
            EXPECT_LT(count, own + s.landing_history + 0.05);
          }
        }
      }
      std::printf("\n");
    }
  }
}

// The same goal on the other shipped scenes, BMFR only (the denoiser whose restart window
// sets the recovery; `none` has no spatial filter): from the third frame after the 40° jump
// the fovea's sharpness within 10% of the fixed-gaze control. Below 0.9 passes only with a
// fovea no worse than the control's against a converged reference (tone-mapped PSNR at most
// 0.5 dB and HDR-FLIP 0.003 below it): less gradient energy is then less noise, not blur
// (glossy-spheres: 0.76-0.90 at frames 3-6, HDR-FLIP 0.018-0.028 better, PSNR +1.7 dB to
// −0.44 dB; the control, a still view, converges without TAA and keeps the noisier
// highlights). Scores are printed, not
// bounded otherwise: 8 frames after the jump hold fewer samples than the control's history
// (stereo-occluders stays 1.1-2.4 dB below it; docs/reconstruction.md).
// A shipped scene's name as a test name ("stereo-occluders" -> "stereooccluders").
std::string scene_test_name(const ::testing::TestParamInfo<const char*>& i) {
  std::string n = i.param;
  std::erase(n, '-');
  return n;
}

class SaccadeRecoveryPerScene : public GpuTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(SaccadeRecoveryPerScene, BmfrRecoversWithinThreeFrames) {
  const CurveSetting c(GetParam());
  renderer::GpuScene gs(ctx(), c.scene, {}, fovea::test::kStatisticsTracing);
  reconstruct::ReconSettings s;
  s.denoiser = reconstruct::Denoiser::Bmfr;
  pipeline::FramePipeline control(ctx(), gs, core::stereo_views(c.display), {}, s, c.path, true);
  pipeline::FramePipeline jump(ctx(), gs, core::stereo_views(c.display), {}, s, c.path, true);
  fovea::test::FoveaReference ref;
  std::printf("%s, bmfr: sharpness / control [fovea PSNR dB, HDR-FLIP | the control's] per frame after the jump:",
              GetParam());
  for (int f = 0; f < c.settle + c.after; ++f) {
    control.render(c.poses, {c.target, c.target}, std::uint32_t(f));
    const glm::dvec3 gaze = f < c.settle ? c.before : c.target;
    jump.render(c.poses, {gaze, gaze}, std::uint32_t(f));
    if (ref.image.pixels.empty())  // the view holds the eye's pose once a frame was rendered
      ref = fovea_reference(ctx(), gs, control.view(core::Eye::Left), c.target, 1024);
    if (f < c.settle) continue;
    const int k = f - c.settle + 1;  // frames since the jump
    const double r = fovea_sharpness(jump.image(core::Eye::Left), jump.view(core::Eye::Left), c.target) /
                     fovea_sharpness(control.image(core::Eye::Left), control.view(core::Eye::Left), c.target);
    const core::Scores q = fovea::test::fovea_scores(jump.image(core::Eye::Left), ref);
    const core::Scores qc = fovea::test::fovea_scores(control.image(core::Eye::Left), ref);
    std::printf(" %.3f [%.2f %.3f | %.2f %.3f]", r, q.psnr, q.hdr_flip, qc.psnr, qc.hdr_flip);
    ASSERT_TRUE(std::isfinite(r));
    if (k >= 3) {
      EXPECT_LE(r, 1.1) << GetParam() << ", frame " << k;
      if (r < 0.9) {  // the default scene's tolerances (GpuTest.SaccadeRecoveryCurveOnTheDefaultScene)
        EXPECT_GE(q.psnr, qc.psnr - 0.5) << GetParam() << ", frame " << k << ": smoother than the control, and worse";
        EXPECT_LE(q.hdr_flip, qc.hdr_flip + 0.003)
            << GetParam() << ", frame " << k << ": smoother than the control, and worse";
      }
    }
  }
  std::printf("\n");
}

INSTANTIATE_TEST_SUITE_P(ShippedScenes, SaccadeRecoveryPerScene,
                         ::testing::Values("cornell", "glossy-spheres", "stereo-occluders"),
                         scene_test_name);

// A 32° gaze step as `fovea render` renders it: a shipped scene from its camera on `small`,
// the gaze at −16° before, +16° after.
struct SmallStep {
  renderer::Scene scene;
  core::DisplayPreset display = core::load_display("small");
  std::array<core::Pose, 2> poses;
  glm::dvec3 before = fovea::test::horizontal_gaze(-16), target = fovea::test::horizontal_gaze(16);

  explicit SmallStep(const char* name) : scene(renderer::load_scene(name)), poses(core::eye_poses(scene.camera, display)) {}
};

// BMFR is never worse than no denoiser on the frames after a landing (docs/reconstruction.md,
// "A 32° gaze step"), as `fovea render` renders it: `small`, both eyes, the frame defaults (one
// sample per cell, the new fovea's extra samples, stereo gather), a 32° step. On the landing
// frame TAA takes no history in the new fovea (ReconSettings::landing_deg): that history was
// the previous frame's periphery, resampled within the cell-size test's limits, and blended in
// it made BMFR's first frame the worse (stereo-occluders: 0.389 against 0.274 fovea HDR-FLIP).
class LandingBmfrAgainstNone : public GpuTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(LandingBmfrAgainstNone, BmfrIsNoWorseOnAnyFrameAfterTheLanding) {
  const SmallStep c(GetParam());
  const auto& [display, poses, before, target] = std::tie(c.display, c.poses, c.before, c.target);
  renderer::GpuScene gs(ctx(), c.scene, {}, fovea::test::kStatisticsTracing);
  constexpr int kSettle = 10;
  fovea::test::FoveaReference ref;
  std::array<std::vector<double>, 2> flip;  // none, bmfr
  for (const auto denoiser : {reconstruct::Denoiser::None, reconstruct::Denoiser::Bmfr}) {
    reconstruct::ReconSettings s = pipeline::FrameConfig::default_recon();
    s.denoiser = denoiser;
    pipeline::FramePipeline jump(ctx(), gs, core::stereo_views(display), {}, s);
    for (int f = 0; f < kSettle + int(reconstruct::kLandingFrames); ++f) {
      const glm::dvec3 gaze = f < kSettle ? before : target;
      jump.render(poses, {gaze, gaze}, std::uint32_t(f));
      if (ref.image.pixels.empty())
        ref = fovea_reference(ctx(), gs, jump.view(core::Eye::Left), target, 256);
      if (f >= kSettle) {
        const double score = fovea::test::fovea_scores(jump.image(core::Eye::Left), ref).hdr_flip;
        flip[denoiser == reconstruct::Denoiser::Bmfr].push_back(score);
      }
    }
  }
  std::printf("%s: fovea HDR-FLIP per frame after the landing, bmfr / none:", GetParam());
  for (std::size_t k = 0; k < flip[0].size(); ++k) {
    std::printf(" %.3f / %.3f", flip[1][k], flip[0][k]);
    EXPECT_LE(flip[1][k], flip[0][k] + 0.003) << GetParam() << ", frame " << k + 1 << " after the landing";
  }
  std::printf("\n");
}

INSTANTIATE_TEST_SUITE_P(ShippedScenes, LandingBmfrAgainstNone, ::testing::Values("default", "stereo-occluders"),
                         scene_test_name);

// Saccade recovery within 50 ms (docs/reconstruction.md, "A 32° gaze step"): as `fovea render`
// renders it (`small`, both eyes, the frame defaults, BMFR), 30 frames at −16° and a 32° step,
// the fovea's HDR-FLIP on the 4th frame from the landing (57 ms at 70 Hz) within 10 % of the
// steady value: the 40th frame of a gaze held at +16° from the start. Before the landed
// fovea's history was capped (ReconSettings::landing_history) and it traced 8 samples per
// cell, tools/recovery-curves.sh measured 1.17-1.51 on these scenes (BMFR).
class LandingRecovery : public GpuTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(LandingRecovery, WithinTenPercentOfSteadyByTheFourthFrame) {
  const SmallStep c(GetParam());
  const auto& [display, poses, before, target] = std::tie(c.display, c.poses, c.before, c.target);
  renderer::GpuScene gs(ctx(), c.scene, {}, fovea::test::kStatisticsTracing);
  constexpr int kSettle = 30, kSteady = 40;
  const reconstruct::ReconSettings s = pipeline::FrameConfig::default_recon();
  fovea::test::FoveaReference ref;
  pipeline::FramePipeline steady(ctx(), gs, core::stereo_views(display), {}, s);
  for (int f = 0; f < kSteady; ++f) steady.render(poses, {target, target}, std::uint32_t(f));
  ref = fovea_reference(ctx(), gs, steady.view(core::Eye::Left), target, 256);
  const double control = fovea::test::fovea_scores(steady.image(core::Eye::Left), ref).hdr_flip;
  pipeline::FramePipeline jump(ctx(), gs, core::stereo_views(display), {}, s);
  std::printf("%s: fovea HDR-FLIP per frame after the landing / steady %.4f:", GetParam(), control);
  for (int f = 0; f < kSettle + int(reconstruct::kLandingFrames); ++f) {
    const glm::dvec3 gaze = f < kSettle ? before : target;
    jump.render(poses, {gaze, gaze}, std::uint32_t(f));
    if (f < kSettle) continue;
    const double r = fovea::test::fovea_scores(jump.image(core::Eye::Left), ref).hdr_flip / control;
    std::printf(" %.3f", r);
    ASSERT_TRUE(std::isfinite(r));
    if (f == kSettle + int(reconstruct::kLandingFrames) - 1) {
      EXPECT_LE(r, 1.1) << GetParam();
    }
  }
  std::printf("\n");
}

INSTANTIATE_TEST_SUITE_P(ShippedScenes, LandingRecovery,
                         ::testing::Values("default", "cornell", "glossy-spheres", "stereo-occluders"),
                         scene_test_name);
