// Stereo sharing of indirect diffuse on the stereo-occluders scene: gathering the other
// eye's samples raises indirect PSNR, and never pulls data across a disocclusion.
#include <cmath>
#include <numbers>

#include <glm/gtc/quaternion.hpp>

#include "fovea/core/metrics.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

namespace {
// Row coordinate in column c of the φ at row coordinate v of column c0: columns packed to
// their visible arcs start and span differently (docs/visual-polar.md).
double row_in_column(const std::vector<fovea::shaders::GridColumn>& t, int c0, double v, int c) {
  const double turn = 2 * std::numbers::pi;
  const auto arc = [&](int k) { return 1.0 - t[std::size_t(k)].phi_gap / turn; };
  double x = t[std::size_t(c0)].phi0 / turn + v / t[std::size_t(c0)].rows * arc(c0) - t[std::size_t(c)].phi0 / turn;
  x -= std::floor(x);
  return x / arc(c) * t[std::size_t(c)].rows;
}
}  // namespace

TEST_F(GpuTest, StereoGatherRaisesIndirectPsnrAndRespectsDisocclusions) {
  const renderer::Scene scene = renderer::load_scene("stereo-occluders");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(96, 108);
  reconstruct::ReconSettings off, gather;
  off.blur = gather.blur = false;
  gather.share = reconstruct::StereoShare::Gather;
  pipeline::FramePipeline a(ctx(), gs, core::stereo_views(display), {}, off), b(ctx(), gs, core::stereo_views(display), {}, gather);
  const auto poses = core::eye_poses(scene.camera, display);
  const std::array<glm::dvec3, 2> gaze{glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)};
  for (std::uint32_t f = 0; f < 3; ++f) {
    a.render(poses, gaze, f);
    b.render(poses, gaze, f);
  }
  const core::Eye L = core::Eye::Left;
  const auto samples = b.grid_samples(L);
  const auto ref = fovea::test::trace_reference(ctx(), gs, samples, b.view(L), L, 128);
  const auto pos = pipeline::testing::grid_buffer(b, L, pipeline::testing::GridBuffer::Position);
  auto keep = [&](std::size_t i) { return samples[i].flags == 0 && pos[i].w >= 0; };
  const core::Image reference = fovea::test::cells_image(ref.indirect, keep);
  const auto own = pipeline::testing::grid_buffer(a, L, pipeline::testing::GridBuffer::SharedIndirect);  // sharing off: own only
  const auto shared = pipeline::testing::grid_buffer(b, L, pipeline::testing::GridBuffer::SharedIndirect);
  const double p_off = core::psnr(fovea::test::cells_image(own, keep), reference);
  const double p_gather = core::psnr(fovea::test::cells_image(shared, keep), reference);
  std::printf("indirect PSNR: own %.2f dB, gather %.2f dB\n", p_off, p_gather);
  EXPECT_GT(p_gather, p_off + 1.0);

  // Disocclusions: left-eye surface points whose projection into the right eye lands on
  // another surface (a pillar in front) in the whole 3×3 neighbourhood of right-eye cells.
  const auto& dr = b.distribution(core::Eye::Right);
  const core::View vr = b.view(core::Eye::Right);
  const auto rpos = pipeline::testing::grid_buffer(b, core::Eye::Right, pipeline::testing::GridBuffer::Position);
  const auto own_b = pipeline::testing::grid_buffer(b, L, pipeline::testing::GridBuffer::AccIndirect);
  const glm::dquat inv = glm::inverse(vr.pose().orientation);
  int occluded = 0;
  for (std::size_t i = 0; i < pos.size(); ++i) {
    if (!keep(i)) continue;
    const glm::dvec3 p(pos[i]);
    const auto px = vr.dir_to_pixel(inv * (p - vr.pose().position));
    if (!px || !vr.contains_pixel(*px)) continue;
    const auto g = dr.screen_to_grid(*px);
    if (!g) continue;
    bool all_other = true;
    for (int dc = -1; dc <= 1 && all_other; ++dc)
      for (int drow = -1; drow <= 1 && all_other; ++drow) {
        // The same φ in the neighbouring column (rows and arcs differ per column; φ wraps).
        const int c0 = std::clamp(int(g->x), 0, dr.columns() - 1);
        const int c = std::clamp(c0 + dc, 0, dr.columns() - 1);
        const int rows = int(dr.column_table()[c].rows);
        const int r = ((int(std::floor(row_in_column(dr.column_table(), c0, g->y, c))) + drow) % rows + rows) % rows;
        const glm::vec4 q = rpos[std::size_t(r) * dr.padded_columns() + c];
        all_other = q.w >= 0 && glm::length(glm::dvec3(q) - p) > 0.2 * glm::length(p - vr.pose().position);
      }
    if (!all_other) continue;
    ++occluded;
    EXPECT_EQ(shared[i], own_b[i]) << "cell " << i;
  }
  std::printf("%d left-eye cells disoccluded in the right eye\n", occluded);
  // The pillars hide some of the wall from the right eye: 2 cells of the packed grid at this
  // size (more than 3 with full rings), each checked above.
  EXPECT_GE(occluded, 2);
}

TEST_F(GpuTest, StereoAlternateFillsTheUntracedEyeFromTheOther) {
  const renderer::Scene scene = renderer::load_scene("stereo-occluders");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(64, 72);
  reconstruct::ReconSettings s;
  s.share = reconstruct::StereoShare::Alternate;
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), {}, s);
  const auto poses = core::eye_poses(scene.camera, display);
  for (std::uint32_t f = 0; f < 4; ++f) p.render(poses, {glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)}, f);
  for (core::Eye e : {core::Eye::Left, core::Eye::Right}) {
    const auto own = pipeline::testing::grid_buffer(p, e, pipeline::testing::GridBuffer::AccIndirect);
    const auto shared = pipeline::testing::grid_buffer(p, e, pipeline::testing::GridBuffer::SharedIndirect);
    ASSERT_TRUE(fovea::test::all_finite(shared));
    double n_own = 0, n_shared = 0;
    for (std::size_t i = 0; i < own.size(); ++i) n_own += own[i].w, n_shared += shared[i].w;
    EXPECT_GT(n_shared, 1.5 * n_own);  // each eye traced indirect on half of the frames
    ASSERT_TRUE(fovea::test::all_finite(p.image(e).pixels));
  }
}
