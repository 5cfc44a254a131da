// FrameTimes: the CPU time of a frame split into parts that partition the render() call,
// the fence wait apart from the submission.
#include "fovea/renderer/scene_io.hpp"
#include "fovea/core/clock.hpp"
#include "gpu_fixture.hpp"
#include "pipeline_helpers.hpp"

namespace pipeline = fovea::pipeline;
namespace core = fovea::core;
namespace renderer = fovea::renderer;
using fovea::test::GpuTest;

// Structural, not a speed check: the parts are laps of one clock inside the call, so their
// sum cannot exceed the call's own interval. Were the wait still counted inside `submit`
// as well, the sum would exceed it by the wait (the GPU's whole frame on a CPU device).
TEST_F(GpuTest, FrameTimesReportTheFenceWaitApartFromTheSubmission) {
  const renderer::Scene scene = renderer::load_scene("cornell");
  renderer::GpuScene gs(ctx(), scene);
  const core::DisplayPreset display = fovea::test::display_of_size(48, 54);
  pipeline::FramePipeline p(ctx(), gs, core::stereo_views(display), {}, {});
  const auto poses = core::eye_poses(scene.camera, display);
  for (std::uint32_t f = 0; f < 3; ++f) {
    const core::TimeNs start = core::now_ns();
    const pipeline::FrameTimes t = p.render(poses, {glm::dvec3(0, 0, -1), glm::dvec3(0, 0, -1)}, f);
    const double call_ms = core::ns_to_ms(core::now_ns() - start);
    EXPECT_GE(t.wait_cpu_ms, 0.0) << "frame " << f;
    EXPECT_GE(t.submit_cpu_ms, 0.0) << "frame " << f;
    const double stages = t.grid.cpu_ms + t.trace.cpu_ms + t.reconstruct.cpu_ms + t.resolve.cpu_ms;
    EXPECT_DOUBLE_EQ(t.cpu_ms(), stages + t.submit_cpu_ms + t.wait_cpu_ms) << "frame " << f;
    EXPECT_LE(t.cpu_ms(), call_ms + 1e-3) << "frame " << f << ": the parts overlap (wait counted twice?)";
    // The wait is where the device's work is: a frame that traced something waited for it.
    EXPECT_GT(t.wait_cpu_ms, 0.0) << "frame " << f;
  }
}
