#pragma once
// One stereo frame end to end on the GPU, in one submission: grid → trace → reconstruct →
// resolve. Per eye the sample grid follows the gaze (gpu::GridPass, optionally skipping the
// lens' hidden area), the path tracer traces it, the reconstruction stages
// (reconstruct/stages.hpp) filter it in grid space, and the resolve brings it to the
// display. Each stage reports its GPU and CPU time. Test access: pipeline/testing.hpp.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fovea/core/distribution.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/core/image.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/reconstruct/settings.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/path_tracer.hpp"
#include "fovea/shaders/grid.h"

namespace fovea::pipeline {

// Milliseconds one stage took on the GPU (timestamps; 0 without them) and on the CPU
// (monotonic clock, the calling thread) for both eyes.
struct StageTime {
  double gpu_ms = 0;
  double cpu_ms = 0;
};

struct FrameTimes {
  StageTime grid;         // CPU: the distributions' per-frame update (gaze → grid) and upload; GPU: generation
  StageTime trace;        // CPU: recording; GPU: path tracing, and the display pixels' first hits near the gaze
  double pixel_albedo_gpu_ms = 0;  // part of trace: those first hits (ReconSettings::pixel_albedo)
  StageTime reconstruct;  // CPU: grid mappings and recording; GPU: accumulation, sharing, BMFR, post, TAA
  StageTime resolve;      // CPU: recording; GPU: mips, resolve, depth (enable_depth_output), blur
  // Parts of reconstruct: Phase I with the stereo gather, the BMFR regression, Phase III with TAA.
  double accumulate_gpu_ms = 0, bmfr_fit_gpu_ms = 0, post_gpu_ms = 0;
  double mip_gpu_ms = 0, resample_gpu_ms = 0, blur_gpu_ms = 0;  // parts of resolve: its three kernels
  double submit_cpu_ms = 0;    // ending the command buffer and vkQueueSubmit (recording is in the stages)
  double wait_cpu_ms = 0;      // the fence wait until the GPU finished (on a CPU device: its work)
  double temporal_gpu_ms = 0;  // the temporal error's kernel (a measurement, not part of the frame's stages)
  // What each eye's grid did with the gaze it was given (left, right): the direction it used
  // (clamped into the view, or the last valid gaze / view centre for an unusable one).
  std::array<core::GazeStatus, 2> gaze{};
  // The share of the EMA floors this frame kept (reconstruct::with_history_floors): 0 for a
  // still view (history weights 1/n: it converges), 1 once it moved kFullFloorMotionDeg.
  float history_floor = 1;
  // The stages by the names every report and timing record uses.
  std::array<std::pair<const char*, StageTime>, 4> stages() const {
    return {{{"grid", grid}, {"trace", trace}, {"reconstruct", reconstruct}, {"resolve", resolve}}};
  }
  double gpu_ms() const { return grid.gpu_ms + trace.gpu_ms + reconstruct.gpu_ms + resolve.gpu_ms; }
  double cpu_ms() const {
    return grid.cpu_ms + trace.cpu_ms + reconstruct.cpu_ms + resolve.cpu_ms + submit_cpu_ms + wait_cpu_ms;
  }
  // The frame's times as every timing record and report names them (docs/openxr.md, "Timing
  // records"). GPU: the stages, the parts accumulate, bmfr_fit, post, mip, resample and blur,
  // and total. CPU: gaze (reading it, given here), the stages, submit, wait, and total (the
  // gaze read and the pipeline's recording, submission and fence wait).
  std::vector<std::pair<std::string, double>> gpu_record() const;
  std::vector<std::pair<std::string, double>> cpu_record(double gaze_cpu_ms) const;
};

// Mean indirect-diffuse samples per traced cell: the eye's own and after stereo sharing.
struct IndirectSamples {
  double own = 0, effective = 0;
};

// Each eye's lens mask (left, right), where it is known when the pipeline is made.
using EyeMasks = std::array<std::optional<core::ViewMask>, 2>;

class FramePipeline {
 public:
  // `views`: each eye's FOV and raster (their poses are the first frame's default);
  // `mono` renders the left eye only (stereo sharing needs both). `visibility`: as
  // set_visibility from the first frame on, and each eye's grid is laid out for the pixels
  // its mask leaves (a Visual-Polar grid traces the budget there with the cells its layout
  // gives them; set later, its periphery's rows make up the difference).
  FramePipeline(gpu::Context& ctx, const renderer::GpuScene& scene, const core::StereoViews& views,
                const core::DistributionParams& distribution, const reconstruct::ReconSettings& settings,
                const renderer::PathConfig& path = {}, bool mono = false, const EyeMasks& visibility = {});
  ~FramePipeline();
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  // Skip the view pixels `mask` hides for eye `e` from the next frame on: those cells are
  // neither traced nor reconstructed. The mask must have the eye's raster.
  void set_visibility(core::Eye e, const core::ViewMask& mask);

  // Renders one frame. `eye_pose`: world pose of each eye; `gaze`: each eye's view-space
  // gaze. Frame indices key the noise; the history carries over from the previous call.
  FrameTimes render(const std::array<core::Pose, 2>& eye_pose, const std::array<glm::dvec3, 2>& gaze,
                    std::uint32_t frame);
  // Forget the history (the next frame starts fresh).
  void reset();
  // Measure the temporal error of the displayed images on the device from the next frame on
  // (shaders/recon_temporal.comp), so that nothing is read back for it; reset() keeps it.
  void enable_temporal_error();
  // The noise seed (FrameConfig::seed): frame f's random numbers are keyed by
  // f + kSeedStride·seed; the jitter (period 1024) and the stereo parity keep f.
  static constexpr std::uint32_t kSeedStride = 1024;
  void set_seed(std::uint32_t seed);
  // core::temporal_error averaged over the consecutive frame pairs since it was enabled (0
  // before the second frame).
  double temporal_error(core::Eye e) const;

  // Write each frame's display-space depth (depth(), depth_buffer()) from the next frame on.
  // Off at first: only depth compositing reads it, and it costs every pixel of the resample a
  // read, a transform and a store.
  void enable_depth_output();

  core::Image image(core::Eye e) const;  // the displayed image of the last frame
  // The last frame's display-space linear depth, row-major like image(): per pixel the
  // view-space distance along -Z (scene units) of the nearest grid sample's surface; 0 where
  // that sample saw the sky or none exists. For depth compositing; the image ignores it.
  // core::InputError without enable_depth_output(), as for an eye not rendered.
  std::vector<float> depth(core::Eye e) const;
  // The same two on the device, for work that keeps the frame there (the API layer's
  // hand-over): vec4 and float per pixel, row-major, the first width × height elements.
  // Written by each render() (the depth: after enable_depth_output(), else core::InputError).
  const gpu::Buffer& screen_buffer(core::Eye e) const;
  const gpu::Buffer& depth_buffer(core::Eye e) const;
  std::vector<shaders::GridSample> grid_samples(core::Eye e) const;
  std::int64_t traced_cells(core::Eye e) const;  // cells with a sample in the last frame
  std::int64_t hidden_cells(core::Eye e) const;  // cells the visibility mask skipped in the last frame
  IndirectSamples indirect_samples(core::Eye e) const;
  const core::SampleDistribution& distribution(core::Eye e) const;
  core::View view(core::Eye e) const;  // the eye's view with its last pose
  int eyes() const;
  const reconstruct::ReconSettings& settings() const;

 private:
  friend struct Access;  // pipeline/testing.hpp
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fovea::pipeline
