// FramePipeline::depth(): per display pixel the view-space distance along -Z of the grid
// sample its direction falls in (the nearest sample), 0 for the sky; written only when asked for.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "fovea/core/error.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

TEST_F(GpuTest, FramePipelineDepthIsTheNearestSamplesViewZ) {
  const renderer::Scene scene = renderer::load_scene("stereo-occluders");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(48, 54);
  reconstruct::ReconSettings s;
  s.blur = false;
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), {}, s);
  const auto poses = core::eye_poses(scene.camera, display);
  p.enable_depth_output();
  p.render(poses, {glm::dvec3(0.05, 0, -1), glm::dvec3(0.05, 0, -1)}, 3);
  for (core::Eye eye : {core::Eye::Left, core::Eye::Right}) {
    const std::vector<float> depth = p.depth(eye);
    const auto pos = pipeline::testing::grid_buffer(p, eye, pipeline::testing::GridBuffer::Position);
    const auto& d = p.distribution(eye);
    const core::View v = p.view(eye);
    ASSERT_EQ(depth.size(), std::size_t(v.width()) * std::size_t(v.height()));
    const glm::dvec3 forward = v.pose().orientation * glm::dvec3(0, 0, -1);
    int match = 0, surfaces = 0, sky = 0, n = 0;
    for (int y = 0; y < v.height(); ++y)
      for (int x = 0; x < v.width(); ++x) {
        const auto g = d.screen_to_grid({x + 0.5, y + 0.5});
        if (!g) continue;
        ++n;
        const int c = std::clamp(int(std::floor(g->x)), 0, d.columns() - 1);
        const int rows = int(d.column_table()[std::size_t(c)].rows);
        const int r = std::clamp(int(std::floor(g->y)), 0, rows - 1);
        const glm::vec4 q = pos[std::size_t(r) * std::size_t(d.padded_columns()) + std::size_t(c)];
        const bool surface = q.w >= 0 || q.w <= -2.5f;
        const double expected = surface ? glm::dot(glm::dvec3(q) - v.pose().position, forward) : 0.0;
        const float got = depth[std::size_t(y) * std::size_t(v.width()) + std::size_t(x)];
        ASSERT_TRUE(std::isfinite(got) && got >= 0);
        surfaces += got > 0 ? 1 : 0;
        sky += got == 0 ? 1 : 0;
        match += std::abs(got - expected) <= 1e-4 * std::max(1.0, expected) ? 1 : 0;
      }
    std::printf("eye %d: %d of %d pixels match the nearest cell, %d surface, %d sky\n", int(eye), match, n, surfaces,
                sky);
    EXPECT_GE(match, int(0.97 * n));  // cell-boundary pixels may round to the neighbouring cell
    EXPECT_GT(surfaces, n / 2);
  }
}

// Off by default: the frame writes no depth (only depth compositing reads it), asking for it
// is refused by name, and writing it leaves the image as it was.
TEST_F(GpuTest, FramePipelineDepthOnlyWhenAskedFor) {
  const renderer::Scene scene = renderer::load_scene("stereo-occluders");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(40, 44);
  const auto poses = core::eye_poses(scene.camera, display);
  const std::array<glm::dvec3, 2> gaze{glm::dvec3(0.05, 0, -1), glm::dvec3(0.05, 0, -1)};
  pipeline::FramePipeline plain(ctx(), gs, core::stereo_views(display), {}, reconstruct::ReconSettings{});
  pipeline::FramePipeline with_depth(ctx(), gs, core::stereo_views(display), {}, reconstruct::ReconSettings{});
  with_depth.enable_depth_output();
  for (std::uint32_t f = 0; f < 3; ++f) {
    plain.render(poses, gaze, f);
    with_depth.render(poses, gaze, f);
  }
  for (core::Eye eye : {core::Eye::Left, core::Eye::Right}) {
    EXPECT_THROW(
        {
          try {
            (void)plain.depth(eye);
          } catch (const core::InputError& e) {
            EXPECT_NE(std::string(e.what()).find("depth output is off"), std::string::npos) << e.what();
            throw;
          }
        },
        core::InputError);
    EXPECT_THROW((void)plain.depth_buffer(eye), core::InputError);
    const std::vector<float> depth = with_depth.depth(eye);
    EXPECT_TRUE(std::any_of(depth.begin(), depth.end(), [](float d) { return d > 0; }));
    const core::Image a = plain.image(eye), b = with_depth.image(eye);
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(a.pixels[0])), 0);
  }
}
