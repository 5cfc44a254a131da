#pragma once
// Test access to FramePipeline's internals: grid-space buffers, filling every buffer with a
// pattern, resolving a given grid image. Not for tools: their numbers come from the public API.
#include <cstdint>
#include <vector>

#include <glm/vec4.hpp>

#include "fovea/pipeline/frame_pipeline.hpp"

namespace fovea::pipeline::testing {

// Grid-space buffers (padded grid layout) of the last frame.
enum class GridBuffer {
  Radiance,        // the path tracer's plain radiance (the "1 spp input")
  AccDirect,       // Phase I direct+specular (demodulated, .w count)
  AccIndirect,     // Phase I indirect diffuse (demodulated, .w count)
  SharedIndirect,  // after stereo sharing (.w effective count)
  Fitted,          // BMFR weighted sum (demodulated); only with the BMFR denoiser
  Final,           // remodulated output in grid space (.w = 1 where a sample exists)
  Albedo,          // the path tracer's first-hit albedo, this frame
  AccAlbedo,       // Phase I's accumulated albedo (what TAA re-modulates with)
  Position,        // validation data: world position (sky: direction), .w material (-2: no sample)
  TapWeight,       // Phase I's weights of its four history taps (renormalised; 0: none)
};

std::vector<glm::vec4> grid_buffer(const FramePipeline& p, core::Eye e, GridBuffer which);

// Overwrites every device buffer the pipeline writes per frame (grid, the path tracer's
// outputs, history, reconstruction and screen buffers; not BMFR's internal ones) with the
// 32-bit `word`, and forgets the history: tests fill them with a NaN pattern to show that
// no stage reads memory the frames since have not written.
void fill_buffers(FramePipeline& p, std::uint32_t word);

// The order in which the path tracer takes eye `e`'s cells: the live tiles (the pipeline's),
// or the one set_trace_order forced. set_trace_order makes it take every
// grid's cells in `order` from the next frame on, and the reconstruction's per-cell kernels
// over the live tiles for TraceOrder::Live, over every cell for the others (whatever the
// device); for tests and benchmarks of the order.
renderer::TraceOrder trace_order(const FramePipeline& p, core::Eye e);
void set_trace_order(FramePipeline& p, renderer::TraceOrder order);
// The cells of the tiles the last frame's grid pass listed as live for eye `e`, in the order the
// trace's invocations take them (with the cells without a sample in those tiles).
std::vector<std::uint32_t> live_cells(const FramePipeline& p, core::Eye e);

// Resolves a grid image given in the padded grid layout (premultiplied rgb, .w coverage)
// with eye `e`'s current mapping, optionally blurred; for round-trip tests.
core::Image resolve_grid(FramePipeline& p, core::Eye e, const std::vector<glm::vec4>& grid, bool blur);

// Runs only the peripheral blur on a display image (the eye's raster) with eye `e`'s current
// mapping; for measuring the kernel.
core::Image blur_image(FramePipeline& p, core::Eye e, const core::Image& image);

// Runs only the grid-space peripheral blur (angular polar grids) on a grid image in the padded
// grid layout with eye `e`'s current mapping; the blurred grid. For measuring the kernel.
std::vector<glm::vec4> blur_grid(FramePipeline& p, core::Eye e, const std::vector<glm::vec4>& grid);

// Per display pixel of eye `e` (row-major), the grid coordinate the resolve samples with the
// current mapping: (u = column coordinate, t = φ/2π or y/height, LOD, 0).
std::vector<glm::vec4> resolve_grid_coords(FramePipeline& p, core::Eye e);

// Resolving the last frame again, one submission per part (the grid image's copy into the
// mip chain, the φ-mip chain, the resample with the display-space depth, the optional
// blur in grid space and on the display, counted together): per part the GPU milliseconds
// (timestamps; 0 without them) and the process's CPU milliseconds over the submission (all
// threads: on a CPU device the work itself, which other processes on the machine do not
// inflate the way they inflate elapsed time). For the resolve benchmark.
struct KernelTime {
  double gpu_ms = 0, cpu_ms = 0;
};
struct ResolveKernelTimes {
  KernelTime copy, mip, resample, blur;
};
ResolveKernelTimes time_resolve(FramePipeline& p, bool blur);

// Reconstructing the last frame again the same way, one submission per pass (Phase I
// accumulation, stereo gather, BMFR fit — zero without BMFR —, Phase III, TAA), both eyes;
// the history is the one the last frame read. Always as for a moving view (the pipeline's
// settings without this frame's motion, the grid reprojected), as a headset's frames run,
// whatever the last frame's motion was. For the BMFR chain benchmark.
struct ReconKernelTimes {
  KernelTime accumulate, share, fit, post, taa;
};
ReconKernelTimes time_reconstruct(FramePipeline& p, std::uint32_t frame);

// Tracing the last frame's grids again, both eyes in one submission, with the cells taken in
// `order`, with the pipeline's path configuration (both eyes trace indirect light); `frame`
// keys the random numbers. For the trace-cost benchmark.
KernelTime time_trace(FramePipeline& p, std::uint32_t frame, renderer::TraceOrder order);

}  // namespace fovea::pipeline::testing
