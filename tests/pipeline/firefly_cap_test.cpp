// Fireflies are capped in grid space before the resolve spreads a cell over its pixels
// (recon_taa.comp, docs/reconstruction.md "Textures under sparse
// cells, fireflies, history resampling"): at budget 0.01 a cell of the scaled
// raster covers ~100 display pixels, and one 1-spp outlier became a blob. No surface cell
// leaves TAA brighter than kFireflyRatio (4) times its brightest grid neighbour, on frames
// whose traced radiance holds such outliers; emitters and the sky are never capped.
#include <algorithm>
#include <cstdio>

#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace firefly_cap {

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

constexpr double kRatio = 4.0;

double luma(glm::vec4 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

// Per surface cell of a columns × rows raster (row-major, padded to `pitch` columns): its
// luminance over the largest luminance of its 3×3 neighbours that hold a sample; the largest
// such ratio over the grid (cells without a lit neighbour skipped).
double worst_ratio(const std::vector<glm::vec4>& v, const std::vector<glm::vec4>& pos, int columns, int rows, int pitch) {
  double worst = 0;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) {
      const std::size_t i = std::size_t(r) * pitch + c;
      if (pos[i].w < 0) continue;  // sky, emitter or no sample
      double brightest = 0;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          const int rr = r + dr, cc = c + dc;
          if ((dr == 0 && dc == 0) || rr < 0 || rr >= rows || cc < 0 || cc >= columns) continue;
          const std::size_t j = std::size_t(rr) * pitch + cc;
          if (pos[j].w > -1.5 || pos[j].w < -2.5) brightest = std::max(brightest, luma(v[j]));  // has a sample
        }
      if (brightest > 0) worst = std::max(worst, luma(v[i]) / brightest);
    }
  return worst;
}

TEST_F(GpuTest, FirefliesAreCappedBeforeTheResolve) {
  const renderer::Scene scene = renderer::load_scene("default");
  const renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = core::load_display("small");
  core::DistributionParams d;
  d.kind = core::DistributionKind::CartesianUniform;
  d.budget = 0.01;
  for (reconstruct::Denoiser den : {reconstruct::Denoiser::None, reconstruct::Denoiser::Bmfr}) {
    reconstruct::ReconSettings s;
    s.denoiser = den;
    pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), d, s, {}, /*mono=*/true);
    const auto& dist = p.distribution(core::Eye::Left);
    const auto poses = core::eye_poses(scene.camera, display);
    double input_worst = 0, output_worst = 0;
    for (std::uint32_t f = 0; f < 8; ++f) {
      p.render(poses, {dist.view().centre_dir(), dist.view().centre_dir()}, f);
      const auto pos = pipeline::testing::grid_buffer(p, core::Eye::Left, pipeline::testing::GridBuffer::Position);
      const auto radiance = pipeline::testing::grid_buffer(p, core::Eye::Left, pipeline::testing::GridBuffer::Radiance);
      const auto final = pipeline::testing::grid_buffer(p, core::Eye::Left, pipeline::testing::GridBuffer::Final);
      input_worst = std::max(input_worst, worst_ratio(radiance, pos, dist.columns(), dist.rows(), dist.padded_columns()));
      output_worst = std::max(output_worst, worst_ratio(final, pos, dist.columns(), dist.rows(), dist.padded_columns()));
    }
    std::printf("%s: largest cell / brightest neighbour: traced %.1f, after TAA %.3f\n",
                den == reconstruct::Denoiser::Bmfr ? "bmfr" : "none", input_worst, output_worst);
    EXPECT_GT(input_worst, kRatio);  // the frames hold fireflies to cap
    EXPECT_LE(output_worst, kRatio * (1 + 1e-4));
  }
}

}  // namespace firefly_cap
