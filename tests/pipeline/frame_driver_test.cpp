// The frame driver every entry point sets its frames up with (pipeline/frame_driver.hpp): the
// display's views with the head at the scene's camera and the lens hidden area culled, or the
// views it is given with nothing culled; the frame configuration reaches the pipeline.
#include <glm/gtc/quaternion.hpp>

#include "fovea/core/eye_optics.hpp"
#include "fovea/pipeline/frame_driver.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"

namespace pipeline = fovea::pipeline;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

namespace {
double pose_distance(const core::Pose& a, const core::Pose& b) {
  return glm::length(a.position - b.position) + glm::length(a.orientation - b.orientation);
}
}  // namespace

TEST_F(GpuTest, FrameDriverSetsUpEveryEntryPointAlike) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  const core::DisplayPreset display = core::load_display("tiny");
  pipeline::FrameConfig frame;
  frame.distribution.budget = 0.2;
  frame.tracing = renderer::Tracing::Compute;
  pipeline::finish(frame, true);

  // The command-line tools: the preset's views at the scene's camera, the lens hidden area culled.
  pipeline::FrameDriver tools(ctx(), scene, display, {frame, true, false});
  EXPECT_EQ(tools.trace_choice().tracing, renderer::Tracing::Compute);
  EXPECT_EQ(tools.pipeline().distribution(core::Eye::Left).params().budget, 0.2);
  const auto expected = core::eye_poses(scene.camera, display);
  for (std::size_t e = 0; e < 2; ++e) EXPECT_LT(pose_distance(tools.static_poses()[e], expected[e]), 1e-12);
  const std::array<glm::dvec3, 2> gaze{glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)};
  tools.pipeline().render(tools.static_poses(), gaze, 0);
  EXPECT_GT(tools.pipeline().hidden_cells(core::Eye::Left), 0);
  EXPECT_GT(tools.pipeline().hidden_cells(core::Eye::Right), 0);

  pipeline::FrameDriver uncut(ctx(), scene, display, {frame, false, false});
  uncut.pipeline().render(uncut.static_poses(), gaze, 0);
  EXPECT_EQ(uncut.pipeline().hidden_cells(core::Eye::Left), 0);

  // The layer: the application's views, its eye poses in the reference space placed at the
  // scene's camera; nothing culled until it sets the runtime's hidden area.
  const core::StereoViews views = core::stereo_views(display);
  pipeline::FrameDriver layer(ctx(), scene, views, {frame, true, false});
  const core::Pose identity{};
  EXPECT_LT(pose_distance(layer.at_camera(identity), scene.camera), 1e-12);
  const auto app = views.poses();  // the head at the reference space's origin
  for (std::size_t e = 0; e < 2; ++e)
    EXPECT_LT(pose_distance(layer.at_camera(app[e]), expected[e]), 1e-9) << "eye " << e;
  layer.pipeline().render({layer.at_camera(app[0]), layer.at_camera(app[1])}, gaze, 0);
  EXPECT_EQ(layer.pipeline().hidden_cells(core::Eye::Left), 0);
  EXPECT_EQ(layer.pipeline().distribution(core::Eye::Left).params().budget, 0.2);
}

// A fixating eye's drift does not move the grid: within kGridHoldDeg (0.5°) of the gaze the
// grid was laid out for it stays there; a larger move, and the first frame after reset(),
// lay it out again at the gaze.
TEST_F(GpuTest, GridHoldsStillThroughAFixationalDrift) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = core::load_display("tiny");
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), {}, {}, {}, /*mono=*/true);
  const auto poses = core::eye_poses(scene.camera, display);
  const auto at = [](double yaw_deg) {
    const double a = glm::radians(yaw_deg);
    return glm::dvec3(std::sin(a), 0, -std::cos(a));
  };
  const auto used = [&](double yaw_deg, std::uint32_t f) {
    return p.render(poses, {at(yaw_deg), at(yaw_deg)}, f).gaze[0].used;
  };
  EXPECT_LT(glm::length(used(2.0, 0) - at(2.0)), 1e-9);
  EXPECT_LT(glm::length(used(2.3, 1) - at(2.0)), 1e-9) << "0.3°: held";
  EXPECT_LT(glm::length(used(1.6, 2) - at(2.0)), 1e-9) << "0.4° the other way: held";
  EXPECT_LT(glm::length(used(2.8, 3) - at(2.8)), 1e-9) << "0.8°: laid out again";
  EXPECT_LT(glm::length(used(3.1, 4) - at(2.8)), 1e-9) << "held at the new place";
  p.reset();
  EXPECT_LT(glm::length(used(3.1, 5) - at(3.1)), 1e-9) << "after reset";
}
