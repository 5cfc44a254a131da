#pragma once
// FramePipeline's state, shared by frame_pipeline.cpp and the test access (testing.cpp).
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "fovea/core/grid_hold.hpp"
#include "fovea/gpu/grid_pass.hpp"
#include "fovea/gpu/timer.hpp"
#include "fovea/pipeline/frame_pipeline.hpp"
#include "fovea/reconstruct/grid_map.hpp"
#include "fovea/reconstruct/stages.hpp"
#include "fovea/renderer/display_albedo.hpp"

namespace fovea::pipeline {

struct EyeState {
  core::Eye eye = core::Eye::Left;
  std::unique_ptr<core::SampleDistribution> dist;
  core::View base_view;
  core::Pose pose;
  glm::dvec3 gaze_used{0, 0, -1};  // the gaze the grid used in the last frame
  core::GridHold hold;              // where the grid is laid out (through a fixational drift)
  std::unique_ptr<gpu::GridPass> grid_pass;
  gpu::Buffer grid;
  renderer::TraceOutputs trace;
  renderer::PrimaryHits primary;  // the display pixels' first hits near the gaze (pixel albedo)
  std::uint32_t cells = 0;
  std::unique_ptr<reconstruct::GridMapping> mapping;
  std::vector<std::uint32_t> mask;  // ViewMask words; empty: every cell is visible
};

struct FramePipeline::Impl {
  gpu::Context& ctx;
  reconstruct::ReconSettings settings;
  renderer::PathConfig path;
  renderer::PathTracer tracer;
  std::vector<std::unique_ptr<EyeState>> eyes;
  std::unique_ptr<reconstruct::Accumulation> accumulation;
  std::unique_ptr<reconstruct::StereoGather> gather;
  std::unique_ptr<reconstruct::Bmfr> bmfr;  // null without the BMFR denoiser
  std::unique_ptr<reconstruct::PostTaa> post;
  std::unique_ptr<reconstruct::Resolve> resolve;
  std::unique_ptr<renderer::DisplayAlbedo> pixel_albedo;  // null: no pixel albedo (ReconSettings::pixel_albedo)
  gpu::GpuTimer timer;
  std::uint32_t frames_done = 0;  // frames since the last reset
  std::uint32_t landing_left = 0;  // frames still tracing the new fovea's extra samples
  int parity = 0;                 // history buffers written by the last frame
  bool temporal = false;          // the temporal error is measured on the device
  std::uint32_t seed = 0;         // FramePipeline::set_seed
  std::uint32_t temporal_frames = 0, temporal_pairs = 0;  // frames measured, consecutive pairs summed
  // testing::set_trace_order; it also sets settings.live_cells (to whether the order is Live)
  std::optional<renderer::TraceOrder> forced_order;

  Impl(gpu::Context& c, const renderer::GpuScene& scene, const renderer::PathConfig& p,
       const reconstruct::ReconSettings& s)
      : ctx(c), settings(s), path(p), tracer(c, scene), timer(c) {}

  const EyeState* other(const EyeState& e) const {
    if (eyes.size() < 2) return nullptr;
    return eyes[0].get() == &e ? eyes[1].get() : eyes[0].get();
  }
  void write_mappings() {
    for (auto& e : eyes) {
      const EyeState* o = other(*e);
      e->mapping->write(e->pose, o ? &o->pose : nullptr);
    }
  }
  // Per eye, from the mappings written last: the previous frame's grid but for the jitter.
  std::array<bool, 2> unmoved() const {
    std::array<bool, 2> u{};
    for (std::size_t i = 0; i < eyes.size(); ++i) u[i] = eyes[i]->mapping->unmoved();
    return u;
  }
  // The grid pass's live tiles, in tile order (docs/renderer.md, "Live cells"): no workgroup
  // for a tile without a sample, and vectors of neighbours in φ on polar grids (whose grid-order
  // vectors span radii far apart on the display: docs/reconstruction-history.md, "Coherent
  // Visual-Polar vectors"). Tests force the full dispatches (tile or grid order) to compare.
  renderer::TraceOrder trace_order() const { return forced_order.value_or(renderer::TraceOrder::Live); }
  void fill(std::uint32_t word);
  int index(core::Eye e, const char* what) const;  // throws InputError when `e` is not rendered
};

struct Access {
  static FramePipeline::Impl& impl(const FramePipeline& p) { return *p.impl_; }
};

}  // namespace fovea::pipeline
