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
