// Hidden-area culling: with the lens' view mask set, the cells it hides are neither traced
// nor reconstructed. On full-resolution Cartesian, whose grid the budget does not set, the
// cells the mask leaves visible render as without it; Visual-Polar spends the budget the
// mask frees on the visible field (its rows or its layout change).
#include <cmath>
#include <cstring>
#include <string>
#include <utility>

#include "fovea/core/error.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
namespace shaders = fovea::shaders;
using fovea::test::GpuTest;
using pipeline::testing::GridBuffer;

namespace {
void expect_hidden_cells_untouched(fovea::gpu::Context& ctx, core::DistributionKind kind) {
  SCOPED_TRACE(core::distribution_name(kind));
  const bool same_layout = kind == core::DistributionKind::Cartesian;
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx, scene);
  const core::DisplayPreset display = core::load_display("tiny");
  reconstruct::ReconSettings s;
  s.denoiser = reconstruct::Denoiser::None;
  core::DistributionParams dp;
  dp.kind = kind;
  pipeline::FramePipeline culled(ctx, gs, core::stereo_views(display), dp, s, {}, true);
  pipeline::FramePipeline full(ctx, gs, core::stereo_views(display), dp, s, {}, true);
  const core::ViewMask mask = core::EyeOptics(display, core::Eye::Left).view_mask();
  culled.set_visibility(core::Eye::Left, mask);
  // The mask known when the pipeline is made (as `fovea render` culls): the same cells hidden
  // where the layout is the same.
  pipeline::EyeMasks given_masks;
  given_masks[0] = mask;
  pipeline::FramePipeline given(ctx, gs, core::stereo_views(display), dp, s, {}, true, given_masks);
  // A NaN pattern everywhere first: whatever a hidden cell reads back was written this frame.
  pipeline::testing::fill_buffers(culled, 0x7fc00001u);
  const auto poses = core::eye_poses(scene.camera, display);
  const std::array<glm::dvec3, 2> gaze{glm::normalize(glm::dvec3(0.1, 0.05, -1)), glm::dvec3(0, 0, -1)};
  for (std::uint32_t f = 0; f < 2; ++f) {
    culled.render(poses, gaze, f);
    full.render(poses, gaze, f);
    given.render(poses, gaze, f);
  }
  const auto samples = culled.grid_samples(core::Eye::Left);
  const auto unmasked = full.grid_samples(core::Eye::Left);
  const auto given_samples = given.grid_samples(core::Eye::Left);
  std::int64_t given_hidden = 0;
  for (std::size_t i = 0; i < given_samples.size(); ++i) {
    given_hidden += given_samples[i].flags == shaders::kCellHidden;
    if (same_layout) {
      EXPECT_EQ(given_samples[i].flags, samples[i].flags) << "cell " << i;
    }
  }
  EXPECT_GT(given_hidden, 0);
  EXPECT_EQ(given.hidden_cells(core::Eye::Left), given_hidden);
  const auto radiance = pipeline::testing::grid_buffer(culled, core::Eye::Left, GridBuffer::Radiance);
  const auto position = pipeline::testing::grid_buffer(culled, core::Eye::Left, GridBuffer::Position);
  const auto final_color = pipeline::testing::grid_buffer(culled, core::Eye::Left, GridBuffer::Final);
  const auto full_position = pipeline::testing::grid_buffer(full, core::Eye::Left, GridBuffer::Position);
  std::int64_t hidden = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].flags != shaders::kCellHidden) {
      if (same_layout) {
        EXPECT_EQ(samples[i].flags, unmasked[i].flags) << "cell " << i << ": only the mask differs";
      }
      continue;
    }
    ++hidden;
    if (same_layout) {
      ASSERT_EQ(unmasked[i].flags, 0u) << "cell " << i << " is traced without the mask";
    }
    // Hidden is the cell centre's (its jittered sample may fall either side of the edge).
    const int columns = culled.distribution(core::Eye::Left).padded_columns();
    const shaders::GridSample centre =
        culled.distribution(core::Eye::Left).sample_at(int(i) % columns, int(i) / columns, {0, 0});
    EXPECT_FALSE(mask.visible_at({centre.screen_x, centre.screen_y})) << "cell " << i;
    // Not traced: no thread wrote the tracer's outputs (they keep the fill pattern); not
    // reconstructed: Phase I's "no sample", black.
    std::uint32_t words[4];
    std::memcpy(words, &radiance[i], sizeof(words));
    for (const std::uint32_t w : words) EXPECT_EQ(w, 0x7fc00001u) << "cell " << i;
    EXPECT_EQ(position[i].w, -2.0f) << "cell " << i;
    if (same_layout) {
      EXPECT_NE(full_position[i].w, -2.0f) << "cell " << i << " has a sample without the mask";
    }
    EXPECT_EQ(final_color[i], glm::vec4(0.0f)) << "cell " << i;
  }
  EXPECT_GT(hidden, 0) << "the tiny preset's lens hides the view's corners";
  EXPECT_EQ(culled.hidden_cells(core::Eye::Left), hidden);
  EXPECT_EQ(full.hidden_cells(core::Eye::Left), 0);
  if (same_layout) {
    EXPECT_EQ(culled.traced_cells(core::Eye::Left) + hidden, full.traced_cells(core::Eye::Left));
  }
  EXPECT_TRUE(fovea::test::all_finite(final_color));
  // A mask of another raster is refused.
  const core::ViewMask other = core::EyeOptics(core::load_display("small"), core::Eye::Left).view_mask();
  EXPECT_THROW(culled.set_visibility(core::Eye::Left, other), core::InputError);
}
}  // namespace

TEST_F(GpuTest, FramePipelineNeverTracesHiddenCells) {
  expect_hidden_cells_untouched(ctx(), core::DistributionKind::Cartesian);
  expect_hidden_cells_untouched(ctx(), core::DistributionKind::VisualPolar);
}

// A hidden area that covers the whole view (a runtime's bogus mesh, a display whose lens
// shows nothing) given when the pipeline is made: nothing is traced, and the frames are
// black, finite and pass validation, for the grid laid out by the budget (also with the
// lattice's reconstruction, whose spline reaches two cells) and for the raster.
TEST_F(GpuTest, FramePipelineWithEveryPixelHidden) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = core::load_display("tiny");
  const core::StereoViews views = core::stereo_views(display);
  const std::vector<glm::vec2> vertices{{-10, -10}, {10, -10}, {10, 10}, {-10, 10}};
  const std::vector<std::uint32_t> indices{0, 1, 2, 0, 2, 3};
  pipeline::EyeMasks masks;
  for (core::Eye e : {core::Eye::Left, core::Eye::Right})
    masks[std::size_t(e)] = core::ViewMask::from_hidden_triangles(views[e], vertices, indices, "everything");
  ASSERT_EQ(masks[0]->hidden_fraction(), 1.0);
  for (const auto& [kind, lattice] : {std::pair{core::DistributionKind::VisualPolar, false},
                                      std::pair{core::DistributionKind::VisualPolar, true},
                                      std::pair{core::DistributionKind::Cartesian, false}}) {
    SCOPED_TRACE(std::string(core::distribution_name(kind)) + (lattice ? ", lattice blur" : ""));
    core::DistributionParams dp;
    dp.kind = kind;
    reconstruct::ReconSettings s;
    s.lattice_blur = lattice;
    pipeline::FramePipeline p(ctx(), gs, views, dp, s, {}, false, masks);
    const auto poses = core::eye_poses(scene.camera, display);
    for (std::uint32_t f = 0; f < 2; ++f) p.render(poses, {glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)}, f);
    for (core::Eye e : {core::Eye::Left, core::Eye::Right}) {
      EXPECT_EQ(p.traced_cells(e), 0);
      EXPECT_GT(p.hidden_cells(e), 0);
      const core::Image img = p.image(e);
      double sum = 0;
      for (const auto& px : img.pixels) sum += std::abs(px.x) + std::abs(px.y) + std::abs(px.z);
      EXPECT_TRUE(std::isfinite(sum));
      EXPECT_EQ(sum, 0.0);
    }
  }
}
