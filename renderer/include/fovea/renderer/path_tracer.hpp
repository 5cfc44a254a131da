#pragma once
// The grid path tracer: traces one eye's per-sample rays of any sample grid (a storage
// buffer of shaders::GridSample, index = row * columns + column, cells with flags != 0
// skipped, or only the tiles with a sample listed by the grid pass) and writes per-cell fp32 outputs
// in the same layout (pt_trace.h):
// demodulated radiance split into direct+specular and indirect diffuse, albedo, shading
// normal + linear depth, world position + material id, and plain radiance.
#include <cstdint>
#include <vector>

#include <glm/vec4.hpp>

#include "fovea/core/display.hpp"
#include "fovea/core/view.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/renderer/scene.hpp"
#include "fovea/shaders/grid.h"
#include "fovea/shaders/pt_trace.h"

namespace fovea::renderer {

// How the invocations of a trace take the grid's cells. Every cell is traced by exactly one
// invocation in either order, and its index keys the random numbers and the outputs, so the
// outputs do not depend on the order (docs/renderer.md, "Trace order").
enum class TraceOrder {
  Grid,   // invocation n traces cell n: a SIMD vector runs along a row of the grid
  Tiles,  // tiles of the grid, each SIMD vector down one column (pt_order.h); needs the grid's extents
  // The grid pass's live tiles (gpu::GridPass::live_tiles(), bound with the outputs), an
  // indirect dispatch of a workgroup per tile with a sample, each in tile order: no workgroup
  // starts for a tile without one, and the outputs of cells without a sample stay as they
  // were (the frame pipeline reads none of them).
  Live,
};

// Default: the BMFR/P5 configuration (1 sample per cell, primary hit + NEE, one BSDF
// bounce + NEE, MIS, no Russian roulette).
struct PathConfig {
  std::uint32_t spp = 1;          // samples per cell and frame
  int max_bounces = 1;            // BSDF-sampled bounces after the primary hit; < 0: unlimited
  std::uint32_t rr_start = 1000;  // bounce from which Russian roulette applies (large: off)
  bool jitter = false;            // spread samples over the cell's footprint (anti-aliasing)
  // > 0: the first hit reads its texture's mip level for a ray cone this many cells wide
  // (pt_trace.comp): for one sample per cell and frame (the frame pipeline), where full
  // resolution aliases into rings and per-frame noise. 0 (references): full resolution,
  // their many jittered samples per pixel being the pixel's box filter.
  double texture_cone = 0;
  // Cells within boost_deg of the gaze trace boost_spp samples (at most kPtMaxSppPerDispatch)
  // instead of spp: the frame pipeline's first frames at a new fovea. Only with spp = 1 and
  // no accumulation over dispatches (the tracer's direct/indirect .a then says the count).
  std::uint32_t boost_spp = 0;
  double boost_deg = 0;
  TraceOrder order = TraceOrder::Grid;
};

// A grid's padded extents: cell index = row * columns + column.
struct GridExtent {
  std::uint32_t columns = 0, rows = 0;
};

// Bounce limit and Russian roulette from the scene's albedo (docs/renderer.md), for
// configurations that do not set them: after n bounces a path keeps at most max^n of its
// light, so max_bounces is the least n ≥ 1 with max^n ≤ kAlbedoBounceCutoff (unlimited,
// i.e. Russian roulette alone, when max ≥ 0.999); the expected throughput is mean^k, so
// Russian roulette starts at the least k ≥ 1 with mean^k ≤ kAlbedoRouletteStart (at the
// latest at kAlbedoRouletteLatest). The
// survival probability is the path throughput (the product of the albedo-weighted BSDF
// weights so far), at most 0.95. `base` supplies spp and jitter.
inline constexpr double kAlbedoBounceCutoff = 1e-3;
inline constexpr double kAlbedoRouletteStart = 0.5;
inline constexpr int kAlbedoRouletteLatest = 8;
PathConfig albedo_path_config(const AlbedoStats& albedo, PathConfig base = {});

// The outputs of one grid, with the descriptor set binding them, the scene and the grid.
// The grid buffer and the scene must outlive it.
class TraceOutputs {
 public:
  std::uint32_t cells() const { return cells_; }
  const gpu::Buffer& direct() const { return direct_; }
  const gpu::Buffer& indirect() const { return indirect_; }
  const gpu::Buffer& albedo() const { return albedo_; }
  const gpu::Buffer& normal_depth() const { return normal_depth_; }
  const gpu::Buffer& position_material() const { return position_material_; }
  const gpu::Buffer& radiance() const { return radiance_; }

 private:
  friend class PathTracer;
  std::uint32_t cells_ = 0;
  GridExtent extent_;                   // zero when bound by cell count: grid order only
  const gpu::Buffer* live_ = nullptr;   // the grid pass's live-tile list (live order), or none
  gpu::Buffer direct_, indirect_, albedo_, normal_depth_, position_material_, radiance_;
  gpu::DescriptorSet set_;
};

class PathTracer {
 public:
  // The shader variant of the scene's features (GpuScene::features()), or of `features`,
  // which must cover them (core::InputError otherwise; all on is the full shader).
  PathTracer(gpu::Context& ctx, const GpuScene& scene);
  PathTracer(gpu::Context& ctx, const GpuScene& scene, const SceneFeatures& features);

  // Output buffers for a grid of `cells` GridSample entries held in `grid` (grid order
  // only), or of `extent.columns * extent.rows` cells laid out row by row (either order;
  // tile order needs extents that are whole tiles: core::SampleDistribution's padded ones).
  TraceOutputs bind(const gpu::Buffer& grid, std::uint32_t cells) const;
  // `live`: the grid pass's live-tile list of this grid (live order); it must outlive the outputs.
  TraceOutputs bind(const gpu::Buffer& grid, GridExtent extent, const gpu::Buffer* live = nullptr) const;

  // Records one frame (split into dispatches of at most kPtMaxSppPerDispatch samples).
  // `view` gives the eye pose (world) and the display raster used for jitter; `frame`
  // keys the random numbers together with the cell, the eye and the sample index.
  // accumulated > 0 averages this frame into the outputs that already hold that many
  // frames of config.spp samples (equal weight per sample); 0 overwrites them.
  // Features (normal, depth, position, material) come from the first sample written.
  // Earlier commands touching `out` or the grid must be ordered before it by a barrier.
  void record(VkCommandBuffer cmd, TraceOutputs& out, const core::View& view, core::Eye eye, std::uint32_t frame,
              const PathConfig& config, std::uint32_t accumulated = 0) const;

  const GpuScene& scene() const { return scene_; }

 private:
  gpu::Context& ctx_;
  const GpuScene& scene_;
  gpu::ComputePipeline pipeline_;
  gpu::Buffer no_list_;  // bound in place of a live-tile list (never read then)
};

// Cartesian grid of a view's raster, built on the CPU: one cell per pixel centre.
std::vector<shaders::GridSample> cartesian_grid(const core::View& view);

}  // namespace fovea::renderer
