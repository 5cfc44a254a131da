#pragma once
// One stereo frame end to end on the GPU, in one submission: grid generation per eye
// (the gaze moved), path tracing of the grid, reconstruction in grid space (temporal
// accumulation, stereo sharing of indirect diffuse, BMFR, second accumulation, TAA,
// albedo re-modulation), resolve to the display through the φ-only mip chain, peripheral
// blur. The history of each stage lives in ping-pong buffers kept across frames.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec4.hpp>

#include "fovea/compositor/reconstruct.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/distribution.hpp"
#include "fovea/core/image.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/path_tracer.hpp"

namespace fovea::compositor {

// GPU time of the frame's stages (timestamps), milliseconds; 0 without timestamps.
struct FrameTimes {
  double trace = 0;        // grid generation + path tracing, both eyes
  double reconstruct = 0;  // accumulation, sharing, BMFR, second accumulation, TAA
  double resolve = 0;      // mip chain, resolve, blur
  double total = 0;
  double bmfr_fit = 0;     // part of reconstruct: the regression alone
};

// Grid-space buffers that tests and tools can read back (padded grid layout).
enum class GridBuffer {
  Radiance,        // the path tracer's plain radiance (the "1 spp input")
  AccDirect,       // Phase I direct+specular (demodulated, .w count)
  AccIndirect,     // Phase I indirect diffuse (demodulated, .w count)
  SharedIndirect,  // after stereo sharing (.w effective count)
  Fitted,          // BMFR weighted sum (demodulated)
  Final,           // remodulated output in grid space (.w = 1 where a sample exists)
  Albedo,
  Position,        // validation data: world position (sky: direction), .w material (-2: no sample)
};

class FramePipeline {
 public:
  // `mono` renders the left eye only (stereo sharing needs both).
  FramePipeline(gpu::Context& ctx, const renderer::GpuScene& scene, const core::DisplayPreset& display,
                const core::DistributionParams& distribution, const ReconSettings& settings,
                const renderer::PathConfig& path = {}, bool mono = false);
  ~FramePipeline();
  FramePipeline(const FramePipeline&) = delete;
  FramePipeline& operator=(const FramePipeline&) = delete;

  // Renders one frame. `eye_pose`: world pose of each eye; `gaze`: each eye's view-space
  // gaze. Frame indices key the noise; the history carries over from the previous call.
  FrameTimes render(const std::array<core::Pose, 2>& eye_pose, const std::array<glm::dvec3, 2>& gaze,
                    std::uint32_t frame);
  // Forget the history (the next frame starts fresh).
  void reset();
  // Overwrites every device buffer the pipeline writes per frame (grid, the path tracer's
  // outputs, history, reconstruction and screen buffers; not BMFR's internal ones) with the
  // 32-bit `word`, and forgets the history: tests fill them with a NaN pattern to show that
  // no stage reads memory the frames since have not written.
  void fill_buffers(std::uint32_t word);

  // Resolves a grid image given in the padded grid layout (premultiplied rgb, .w coverage)
  // with eye `e`'s current mapping, optionally blurred; for round-trip tests.
  core::Image resolve_grid(core::Eye e, const std::vector<glm::vec4>& grid, bool blur);

  core::Image image(core::Eye e) const;  // the displayed image of the last frame
  // The last frame's display-space linear depth, row-major like image(): per pixel the
  // view-space distance along -Z (scene units) of the nearest grid sample's surface; 0 where
  // that sample saw the sky or none exists. For depth compositing; the image ignores it.
  std::vector<float> depth(core::Eye e) const;
  std::vector<glm::vec4> grid_buffer(core::Eye e, GridBuffer which) const;
  std::vector<shaders::GridSample> grid_samples(core::Eye e) const;
  std::int64_t traced_cells(core::Eye e) const;  // cells with a sample in the last frame
  const core::SampleDistribution& distribution(core::Eye e) const;
  core::View view(core::Eye e) const;  // the eye's view with its last pose
  int eyes() const;
  const ReconSettings& settings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fovea::compositor
