// Per-frame sub-cell jitter (on by default): with a still camera and gaze, the frames'
// average at edges converges to the anti-aliased reference (each cell's mean radiance over
// its area), while without jitter it stays at the cell centre's value.
#include <cmath>

#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
namespace shaders = fovea::shaders;
namespace gpu = fovea::gpu;
using fovea::test::GpuTest;

namespace {

double luminance(glm::vec4 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

// Per cell: mean plain radiance over `offsets` (cells' sub-cell offsets, in cells), `spp`
// samples at each.
std::vector<double> area_mean(gpu::Context& ctx, const renderer::GpuScene& scene, const core::SampleDistribution& d,
                              const core::View& view, const std::vector<glm::dvec2>& offsets, std::uint32_t spp) {
  const std::size_t cells = std::size_t(d.padded_columns()) * d.padded_rows();
  gpu::Buffer g(ctx, {cells * sizeof(shaders::GridSample), gpu::BufferUsage::Storage, gpu::Memory::DeviceLocal,
                      "test.grid"});
  renderer::PathTracer pt(ctx, scene);
  renderer::TraceOutputs out = pt.bind(g, std::uint32_t(cells));
  std::vector<double> sum(cells, 0.0);
  std::uint32_t frame = 0;
  for (const glm::dvec2 o : offsets) {
    std::vector<shaders::GridSample> grid(cells);
    for (int r = 0; r < d.padded_rows(); ++r)
      for (int c = 0; c < d.padded_columns(); ++c) grid[std::size_t(r) * d.padded_columns() + c] = d.sample_at(c, r, o);
    g.upload(grid);
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      for (std::uint32_t f = 0; f < spp; ++f) {
        if (f) gpu::compute_to_compute(cmd);
        pt.record(cmd, out, view, core::Eye::Left, 1000 + frame++, {}, f);
      }
    });
    const auto rad = out.radiance().download<glm::vec4>();
    for (std::size_t i = 0; i < cells; ++i) sum[i] += luminance(rad[i]) / double(offsets.size());
  }
  return sum;
}

}  // namespace

TEST_F(GpuTest, JitteredFramesConvergeToTheAntiAliasedEdgeForEveryGridFamily) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(80, 90);
  const auto poses = core::eye_poses(scene.camera, display.ipd_m);
  const std::array<glm::dvec3, 2> gaze{glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)};
  reconstruct::ReconSettings s;
  s.denoiser = reconstruct::Denoiser::None;
  s.blur = false;
  s.alpha_min = 1.0f;  // no history: every frame is its own samples, the test averages them
  const std::uint32_t frames = 32;
  for (const auto kind : {core::DistributionKind::VisualPolar, core::DistributionKind::Cartesian}) {
    core::DistributionParams dp;
    dp.kind = kind;
    double err[2] = {0, 0};
    long edges = 0;
    std::vector<double> aa, centre;
    for (int jitter = 0; jitter < 2; ++jitter) {
      dp.jitter = jitter != 0;
      pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), dp, s, {}, true);
      std::vector<double> mean;
      for (std::uint32_t f = 0; f < frames; ++f) {
        p.render(poses, gaze, f);
        const auto fin = pipeline::testing::grid_buffer(p, core::Eye::Left, pipeline::testing::GridBuffer::Final);
        mean.resize(fin.size(), 0.0);
        for (std::size_t i = 0; i < fin.size(); ++i) mean[i] += luminance(fin[i]) / frames;
      }
      const core::SampleDistribution& d = p.distribution(core::Eye::Left);
      if (aa.empty()) {
        // The anti-aliased reference: the cell's area, 4×4 strata (independent of the
        // Halton points), 16 samples each; and the centre's value with as many samples.
        std::vector<glm::dvec2> strata;
        for (int y = 0; y < 4; ++y)
          for (int x = 0; x < 4; ++x) strata.push_back({(x + 0.5) / 4 - 0.5, (y + 0.5) / 4 - 0.5});
        aa = area_mean(ctx(), gs, d, p.view(core::Eye::Left), strata, 16);
        centre = area_mean(ctx(), gs, d, p.view(core::Eye::Left), {glm::dvec2(0)}, 256);
      }
      // Edge cells: where the area mean and the centre's value differ.
      const auto samples = p.grid_samples(core::Eye::Left);
      edges = 0;
      for (std::size_t i = 0; i < mean.size(); ++i) {
        if (samples[i].flags != 0 || std::abs(aa[i] - centre[i]) < 0.1 * std::max(aa[i], 0.05)) continue;
        ++edges;
        err[jitter] += (mean[i] - aa[i]) * (mean[i] - aa[i]);
      }
    }
    const double off = std::sqrt(err[0] / double(edges)), on = std::sqrt(err[1] / double(edges));
    std::printf("%s: %ld edge cells, RMS error to the anti-aliased reference %.4f with jitter, %.4f without\n",
                core::distribution_name(kind), edges, on, off);
    EXPECT_GT(edges, 50);
    EXPECT_LT(on, 0.5 * off);
  }
}
