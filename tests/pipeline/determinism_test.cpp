// Determinism of FramePipeline: the same frames (scene, poses, gaze, frame indices) give
// bit-identical grid buffers and displayed images in a fresh pipeline, after reset(), and
// after every per-frame buffer was filled with NaN (a stage reading memory that the frames
// have not written shows up as a difference or a NaN).
#include <cmath>
#include <cstring>
#include <string>
#include <utility>

#include "fovea/core/eye_optics.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace reconstruct = fovea::reconstruct;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

namespace {

constexpr std::uint32_t kQuietNan = 0x7fc00001u;
constexpr std::uint32_t kRunFrames = 4;

// Everything a frame leaves behind that a test or tool can read, per eye, as raw bytes.
struct Snapshot {
  std::vector<std::string> names;
  std::vector<std::vector<std::uint32_t>> words;

  template <class T>
  void add(std::string name, const std::vector<T>& v) {
    std::vector<std::uint32_t> w(v.size() * sizeof(T) / 4);
    std::memcpy(w.data(), v.data(), w.size() * 4);
    names.push_back(std::move(name));
    words.push_back(std::move(w));
  }
};

// The gaze wanders so that each frame regenerates the grids and reprojects the history.
std::array<glm::dvec3, 2> gaze_of(std::uint32_t f) {
  const glm::dvec3 g = glm::normalize(glm::dvec3(0.08 * std::sin(0.9 * f), 0.05 * std::cos(1.3 * f), -1.0));
  return {g, g};
}

Snapshot render_sequence(pipeline::FramePipeline& p, const std::array<core::Pose, 2>& poses) {
  p.enable_depth_output();
  for (std::uint32_t f = 0; f < kRunFrames; ++f) p.render(poses, gaze_of(f), 10 + f);
  Snapshot s;
  for (int e = 0; e < p.eyes(); ++e) {
    const core::Eye eye = core::Eye(e);
    const std::string tag = e == 0 ? "left " : "right ";
    s.add(tag + "image", p.image(eye).pixels);
    s.add(tag + "depth", p.depth(eye));
    s.add(tag + "grid samples", p.grid_samples(eye));
    const std::pair<pipeline::testing::GridBuffer, const char*> buffers[] = {
        {pipeline::testing::GridBuffer::Radiance, "radiance"},   {pipeline::testing::GridBuffer::AccDirect, "acc direct"},
        {pipeline::testing::GridBuffer::AccIndirect, "acc indirect"}, {pipeline::testing::GridBuffer::SharedIndirect, "shared"},
        {pipeline::testing::GridBuffer::Fitted, "fitted"},       {pipeline::testing::GridBuffer::Final, "final"},
        {pipeline::testing::GridBuffer::Albedo, "albedo"},       {pipeline::testing::GridBuffer::Position, "position"}};
    const auto grid = p.grid_samples(eye);
    for (const auto& [which, name] : buffers) {
      // Without BMFR nothing produces the fitted buffer: it keeps what it was filled with.
      if (which == pipeline::testing::GridBuffer::Fitted && p.settings().denoiser != reconstruct::Denoiser::Bmfr)
        continue;
      auto cells = pipeline::testing::grid_buffer(p, eye, which);
      // The tracer's own outputs of a cell without a sample are nobody's input: the live
      // order starts no thread for it and leaves them as they were.
      if (which == pipeline::testing::GridBuffer::Radiance || which == pipeline::testing::GridBuffer::Albedo)
        for (std::size_t i = 0; i < cells.size(); ++i)
          if (grid[i].flags != 0) cells[i] = glm::vec4(0.0f);
      s.add(tag + name, cells);
    }
  }
  return s;
}

// Bit-exact comparison, buffer by buffer; reports how many 32-bit words differ.
void expect_identical(const Snapshot& a, const Snapshot& b, const char* what) {
  ASSERT_EQ(a.names, b.names);
  for (std::size_t i = 0; i < a.words.size(); ++i) {
    ASSERT_EQ(a.words[i].size(), b.words[i].size()) << what << ": " << a.names[i];
    std::size_t differ = 0, nan = 0;
    for (std::size_t k = 0; k < a.words[i].size(); ++k) {
      differ += a.words[i][k] != b.words[i][k] ? 1 : 0;
      nan += b.words[i][k] == kQuietNan ? 1 : 0;
    }
    EXPECT_EQ(differ, 0u) << what << ": " << a.names[i] << " differs in " << differ << " of " << a.words[i].size()
                          << " words (" << nan << " hold the fill pattern)";
  }
}

void check_determinism(fovea::gpu::Context& ctx, const char* scene_name, const reconstruct::ReconSettings& settings) {
  const renderer::Scene scene = renderer::load_scene(scene_name);
  renderer::GpuScene gs(ctx, scene);
  const core::DisplayPreset display = fovea::test::display_of_size(40, 44);
  const auto poses = core::eye_poses(scene.camera, display);
  Snapshot first;
  {
    pipeline::FramePipeline p(ctx, gs, core::stereo_views(display), {}, settings);
    first = render_sequence(p, poses);
  }
  for (const auto& v : first.words) {
    std::size_t nan = 0;
    for (std::uint32_t w : v) nan += (w & 0x7f800000u) == 0x7f800000u ? 1 : 0;
    ASSERT_EQ(nan, 0u) << "non-finite values in a fresh render";
  }
  pipeline::FramePipeline p(ctx, gs, core::stereo_views(display), {}, settings);
  expect_identical(first, render_sequence(p, poses), "second fresh pipeline");
  // Other frames in between, then reset(): the history of those must not leak in.
  for (std::uint32_t f = 0; f < 3; ++f) p.render(poses, gaze_of(7 + f), 99 + f);
  p.reset();
  expect_identical(first, render_sequence(p, poses), "after reset()");
  pipeline::testing::fill_buffers(p, kQuietNan);
  expect_identical(first, render_sequence(p, poses), "after a NaN fill");
}

}  // namespace

TEST_F(GpuTest, FramePipelineIsDeterministicWithBmfrGatherAndBlur) {
  reconstruct::ReconSettings s;
  s.share = reconstruct::StereoShare::Gather;
  check_determinism(ctx(), "default", s);
}

TEST_F(GpuTest, FramePipelineIsDeterministicWithoutDenoiserAlternating) {
  reconstruct::ReconSettings s;
  s.denoiser = reconstruct::Denoiser::None;
  s.share = reconstruct::StereoShare::Alternate;
  s.blur = false;
  check_determinism(ctx(), "stereo-occluders", s);
}

// The pipeline's order (the grid pass's live tiles: no workgroup for a tile without a sample;
// the reconstruction's per-cell kernels as the device has them), the live tiles for the
// trace and the reconstruction, and the full dispatches in tile and grid order give
// bit-identical buffers and images, under the lens' hidden area and a moving gaze (cells gain
// and lose their samples from frame to frame): the cell keys everything, and the list's reset
// tiles leave every per-cell buffer as the full dispatches do.
TEST_F(GpuTest, FramePipelineTraceOrderChangesNoBufferOrImage) {
  const renderer::Scene scene = renderer::load_scene("default");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(40, 44);
  const auto poses = core::eye_poses(scene.camera, display);
  reconstruct::ReconSettings settings;
  settings.share = reconstruct::StereoShare::Gather;
  for (const auto kind : {core::DistributionKind::VisualPolar, core::DistributionKind::Cartesian}) {
    core::DistributionParams dp;
    dp.kind = kind;
    const auto masked = [&](pipeline::FramePipeline& p) {
      for (core::Eye e : {core::Eye::Left, core::Eye::Right})
        p.set_visibility(e, core::EyeOptics(display, e).view_mask());
    };
    pipeline::FramePipeline a(ctx(), gs, core::stereo_views(display), dp, settings);
    masked(a);
    ASSERT_EQ(pipeline::testing::trace_order(a, core::Eye::Right), renderer::TraceOrder::Live);
    const Snapshot own = render_sequence(a, poses);
    for (const auto other : {renderer::TraceOrder::Live, renderer::TraceOrder::Tiles, renderer::TraceOrder::Grid}) {
      pipeline::FramePipeline b(ctx(), gs, core::stereo_views(display), dp, settings);
      masked(b);
      pipeline::testing::set_trace_order(b, other);
      ASSERT_EQ(pipeline::testing::trace_order(b, core::Eye::Left), other);
      expect_identical(own, render_sequence(b, poses), core::distribution_name(kind));
    }
  }
}
