// A still image converges (docs/reconstruction.md, "History weights"): with the gaze, the
// head and the scene still, the history weights become 1/n, so the fovea's HDR-FLIP against
// a converged reference of the same light transport falls frame after frame and, after 64
// frames, ends well below its 16-frame value, for every distribution. With the EMA floors
// kept (the view moving, or before this rule) it stalls after ~10 frames.
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "fovea/core/acuity.hpp"
#include "fovea/core/flip.hpp"
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

double fovea_hdr_flip(const core::Image& img, const core::Image& ref, const core::View& view) {
  return core::pool(core::error_maps(img, ref, core::flip_ppd(view)), fovea::test::fovea_pixel_weights(view, kGaze[0]))
      .hdr_flip;
}

TEST_F(GpuTest, StillViewConvergesForEveryDistribution) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(kWidth, kHeight);
  const auto poses = core::eye_poses(scene.camera, display);
  const core::StereoViews views = core::stereo_views(display);
  // The render's transport (one bounce, PathConfig{}), converged.
  renderer::ReferenceOptions o;
  o.path.spp = 64;
  o.max_spp = 2048;
  const core::View view(views[core::Eye::Left].fov(), kWidth, kHeight, poses[0]);
  const core::Image ref = renderer::render_reference(ctx(), gs, view, core::Eye::Left, o).image;

  const std::vector<std::uint32_t> checkpoints = {8, 16, 32, 64};
  for (const core::DistributionKind kind :
       {core::DistributionKind::VisualPolar, core::DistributionKind::PaperVisualPolar,
        core::DistributionKind::Cartesian, core::DistributionKind::CartesianUniform,
        core::DistributionKind::LinearFalloff, core::DistributionKind::LogPolar}) {
    core::DistributionParams dp;
    dp.kind = kind;
    if (kind == core::DistributionKind::Cartesian) dp.budget = 1.0;
    pipeline::FramePipeline p(ctx(), gs, views, dp, reconstruct::ReconSettings{}, {}, /*mono=*/true);
    std::vector<double> flip;
    std::uint32_t next = 0;
    for (std::uint32_t f = 0; f < checkpoints.back(); ++f) {
      const pipeline::FrameTimes t = p.render(poses, kGaze, f);
      if (f > 0) {
        EXPECT_EQ(t.history_floor, 0.0f) << "a still view keeps no EMA floor";
      }
      if (f + 1 == checkpoints[next]) {
        flip.push_back(fovea_hdr_flip(p.image(core::Eye::Left), ref, p.view(core::Eye::Left)));
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
}

}  // namespace convergence
