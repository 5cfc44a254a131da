// A still image converges (docs/reconstruction.md, "History weights"): with the gaze, the
// head and the scene still, the history weights become 1/n, so the fovea's HDR-FLIP against
// a converged reference of the same light transport falls frame after frame and, after 64
// frames, ends well below its 16-frame value, for every distribution. With the EMA floors
// kept (the view moving, or before this rule) it stalls after ~10 frames.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "fovea/core/metrics.hpp"
#include "fovea/reconstruct/settings.hpp"
#include "fovea/renderer/reference.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace convergence {

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

constexpr int kWidth = 128, kHeight = 144;  // the tiny preset's optics at this raster
const std::array<glm::dvec3, 2> kGaze{glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)};

// The Cornell box on the test's raster with the tiny preset's optics.
struct Cornell {
  explicit Cornell(fovea::gpu::Context& ctx)
      : scene(renderer::load_scene("cornell")),
        gs(ctx, scene, {}, fovea::test::kStatisticsTracing),
        display(fovea::test::display_of_size(kWidth, kHeight)),
        poses(core::eye_poses(scene.camera, display)),
        views(core::stereo_views(display)) {}
  renderer::Scene scene;
  renderer::GpuScene gs;
  core::DisplayPreset display;
  std::array<core::Pose, 2> poses;
  core::StereoViews views;
};

TEST_F(GpuTest, StillViewConvergesForEveryDistribution) {
  Cornell c(ctx());
  // The render's transport (one bounce, PathConfig{}), converged.
  renderer::ReferenceOptions o;
  o.path.spp = 64;
  o.max_spp = 2048;
  const core::View view(c.views[core::Eye::Left].fov(), kWidth, kHeight, c.poses[0]);
  const fovea::test::FoveaReference ref = fovea::test::fovea_reference(ctx(), c.gs, view, kGaze[0], o);

  const std::vector<std::uint32_t> checkpoints = {8, 16, 32, 64};
  for (const core::DistributionKind kind :
       {core::DistributionKind::VisualPolar, core::DistributionKind::PaperVisualPolar,
        core::DistributionKind::Cartesian, core::DistributionKind::CartesianUniform,
        core::DistributionKind::LinearFalloff, core::DistributionKind::LogPolar}) {
    core::DistributionParams dp;
    dp.kind = kind;
    if (kind == core::DistributionKind::Cartesian) dp.budget = 1.0;
    pipeline::FramePipeline p(ctx(), c.gs, c.views, dp, reconstruct::ReconSettings{}, {}, /*mono=*/true);
    std::vector<double> flip;
    std::uint32_t next = 0;
    for (std::uint32_t f = 0; f < checkpoints.back(); ++f) {
      const pipeline::FrameTimes t = p.render(c.poses, kGaze, f);
      if (f > 0) {
        EXPECT_EQ(t.history_floor, 0.0f) << "a still view keeps no EMA floor";
      }
      if (f + 1 == checkpoints[next]) {
        flip.push_back(fovea::test::fovea_scores(p.image(core::Eye::Left), ref).hdr_flip);
        ++next;
      }
    }
    std::printf("%-18s fovea HDR-FLIP at frames 8/16/32/64: %.4f %.4f %.4f %.4f\n", core::distribution_name(kind),
                flip[0], flip[1], flip[2], flip[3]);
    for (std::size_t k = 1; k < flip.size(); ++k)
      EXPECT_LT(flip[k], flip[k - 1]) << core::distribution_name(kind) << ": frame " << checkpoints[k];
    EXPECT_LT(flip[3], 0.85 * flip[1]) << core::distribution_name(kind) << ": 64 frames against 16";
  }
}

// Every traced cell keeps its whole history while the view holds still or turns by a small
// part of a cell per frame, also where its jittered samples hit different surfaces or the sky
// (the Cornell box's open front, the block's edges): at a low budget a cell spans degrees, and
// tested by surface such cells restarted whenever their sample changed sides (still, at budget
// 0.02: 34-117 of 356-368 cells held fewer than 12 samples, some 1; full Cartesian 7), so
// they never converged and showed single samples. Linear fall-off kills cells at random
// every frame, by design. Still, the grid is unmoved and Phase I takes each cell's own
// history without reprojecting it (GridMapping::unmoved); turning, it reprojects.
TEST_F(GpuTest, StillViewKeepsTheHistoryOfEveryCell) {
  Cornell c(ctx());
  reconstruct::ReconSettings s;
  s.denoiser = reconstruct::Denoiser::None;  // Phase I's counts do not depend on it
  const std::uint32_t frames = 12;
  for (const double turn_deg : {0.0, 0.02}) {  // the head's turn per frame
    for (const core::DistributionKind kind :
         {core::DistributionKind::VisualPolar, core::DistributionKind::PaperVisualPolar,
          core::DistributionKind::Cartesian, core::DistributionKind::CartesianUniform,
          core::DistributionKind::LogPolar}) {
      core::DistributionParams dp;
      dp.kind = kind;
      dp.budget = kind == core::DistributionKind::Cartesian ? 1.0 : 0.02;
      pipeline::FramePipeline p(ctx(), c.gs, c.views, dp, s, {}, /*mono=*/true);
      for (std::uint32_t f = 0; f < frames; ++f) {
        auto turned = c.poses;
        for (core::Pose& pose : turned)
          pose.orientation = glm::angleAxis(glm::radians(turn_deg * f), glm::dvec3(0, 1, 0)) * pose.orientation;
        p.render(turned, kGaze, f);
      }
      const auto acc = pipeline::testing::grid_buffer(p, core::Eye::Left, pipeline::testing::GridBuffer::AccDirect);
      const auto taps = pipeline::testing::grid_buffer(p, core::Eye::Left, pipeline::testing::GridBuffer::TapWeight);
      const auto samples = p.grid_samples(core::Eye::Left);
      int counted = 0, short_history = 0, resampled = 0;
      float fewest = float(frames);
      for (std::size_t i = 0; i < acc.size(); ++i) {
        if (samples[i].flags != 0) continue;
        // Turning, log-polar's innermost cells (105 of its 356 lost history, all within about
        // a pixel of the gaze, 0.01-0.13 px wide) move by several of their sizes per frame,
        // and their history goes by the surface and cell-size tests as under any motion;
        // counted are the cells of a pixel or more.
        if (turn_deg > 0 && samples[i].footprint < 1) continue;
        ++counted;
        if (acc[i].w != float(frames)) ++short_history;
        // Still, the grid is unmoved: each cell takes its own history, whole (the first tap,
        // weight exactly 1), not the reprojection's bilinear weights around it.
        if (taps[i] != glm::vec4(1, 0, 0, 0)) ++resampled;
        fewest = std::min(fewest, acc[i].w);
      }
      std::printf("turning %.2f deg/frame, %-18s %d cells counted, %d with fewer than %u samples (fewest %.0f)\n",
                  turn_deg, core::distribution_name(kind), counted, short_history, frames, fewest);
      EXPECT_GT(counted, 0) << core::distribution_name(kind);
      EXPECT_EQ(short_history, 0) << core::distribution_name(kind) << ", turning " << turn_deg << " deg/frame";
      if (turn_deg == 0) EXPECT_EQ(resampled, 0) << core::distribution_name(kind);
      else EXPECT_GT(resampled, 0) << core::distribution_name(kind) << ": turning reprojects";
    }
  }
}

// The floors follow the view's motion: none when still, in full from 1° per frame, and an
// unusable measurement counts as motion.
TEST(HistoryFloors, ScaleWithTheViewsMotion) {
  const core::Pose still;
  const glm::dvec3 ahead(0, 0, -1);
  EXPECT_EQ(reconstruct::view_motion_deg(ahead, ahead, still, still), 0.0);
  const glm::dvec3 half_degree(std::sin(0.5 * M_PI / 180), 0, -std::cos(0.5 * M_PI / 180));
  EXPECT_NEAR(reconstruct::view_motion_deg(ahead, half_degree, still, still), 0.5, 1e-9);
  core::Pose turned;
  turned.orientation = glm::angleAxis(glm::radians(2.0), glm::dvec3(0, 1, 0));
  EXPECT_NEAR(reconstruct::view_motion_deg(ahead, ahead, still, turned), 2.0, 1e-9);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(reconstruct::view_motion_deg(ahead, glm::dvec3(nan), still, still), reconstruct::kFullFloorMotionDeg);

  const reconstruct::ReconSettings s;
  EXPECT_EQ(reconstruct::with_history_floors(s, 0).alpha_min, 0.0f);
  EXPECT_FLOAT_EQ(reconstruct::with_history_floors(s, 0.5).alpha_min, 0.5f * s.alpha_min);
  EXPECT_FLOAT_EQ(reconstruct::with_history_floors(s, 0.5).taa_alpha, 0.5f * s.taa_alpha);
  EXPECT_EQ(reconstruct::with_history_floors(s, 30).post_alpha_min, s.post_alpha_min);
  // The motion Phase I holds large cells by: unknown until set, which holds none.
  EXPECT_FALSE(std::isfinite(s.motion_deg));
  EXPECT_EQ(reconstruct::with_history_floors(s, 0).motion_deg, 0.0f);
  EXPECT_FLOAT_EQ(reconstruct::with_history_floors(s, 0.5).motion_deg, 0.5f);
  EXPECT_EQ(reconstruct::with_history_floors(s, nan).motion_deg, float(reconstruct::kFullFloorMotionDeg));
}

}  // namespace convergence
