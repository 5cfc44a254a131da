#pragma once
// The reconstruction stages (docs/reconstruction.md), one object each: it owns its kernels,
// its per-eye buffers (ping-pong pairs where the stage keeps history) and descriptor sets,
// and records both eyes' dispatches followed by the barrier its consumers need. Parity p is
// the history slot a frame writes; it reads slot 1 − p.
//   Accumulation (BMFR Phase I) → StereoGather → Bmfr (Phase II) → PostTaa (Phase III, TAA,
//   albedo) → Resolve (φ-only mips, resolve to the display, depth, peripheral blur).
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <vulkan/vulkan.h>

#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/reconstruct/bmfr.hpp"
#include "fovea/reconstruct/grid_map.hpp"
#include "fovea/reconstruct/settings.hpp"

namespace fovea::reconstruct {

// One eye's padded grid and the buffers every stage reads for it.
struct EyeGrid {
  std::uint32_t cells = 0, columns = 0, padded_columns = 0, padded_rows = 0;
  bool polar = true;                   // φ-only mip chain (polar grids) or one level
  std::uint32_t width = 0, height = 0;  // the display raster the grid resolves to
  double max_pixels_per_deg = 0;        // the raster's densest pixels (bounds the blur's reach)
  // The eye's grid mappings: the buffers the kernels bind, and the host's copy of the current
  // one (GridMapping::current).
  const GridMapping* mapping = nullptr;
  const gpu::Buffer* maps() const { return &mapping->maps(); }
  const gpu::Buffer* tables() const { return &mapping->tables(); }
  const gpu::Buffer* luts() const { return &mapping->luts(); }
  // The path tracer's per-cell outputs (renderer::TraceOutputs) and the grid itself.
  const gpu::Buffer *samples = nullptr, *direct = nullptr, *indirect = nullptr, *normal_depth = nullptr,
                    *position_material = nullptr, *albedo = nullptr;
  // The grid pass's live-tile list (gpu::GridPass::live_tiles()): with
  // ReconSettings::live_cells the per-cell kernels run over its live and reset tiles alone.
  const gpu::Buffer* live = nullptr;
  // The display pixels' first hits near the gaze (renderer::PrimaryHits, a window of the
  // display each frame: Resolve::set_detail), or none.
  const gpu::Buffer* primary = nullptr;
};

// A window of display pixels whose first hits EyeGrid::primary holds this frame, and the
// angles from the gaze (cosines) within which the resolve re-modulates the pixels with them
// fully, and beyond which not at all (recon_resolve.comp, detail_gain). Empty: none.
struct DetailWindow {
  std::uint32_t x0 = 0, y0 = 0, width = 0, height = 0;
  float cos_full = 1, cos_none = 1;
};

class Accumulation {
 public:
  Accumulation(gpu::Context& ctx, std::span<const EyeGrid> eyes, const gpu::Buffer& materials);
  // `fresh[e]`: eye e traced new indirect diffuse this frame; `unmoved[e]`: eye e's grid
  // mapping is the previous frame's but for the jitter (GridMapping::unmoved).
  void record(VkCommandBuffer cmd, int parity, bool history, std::span<const bool> fresh,
              std::span<const bool> unmoved, const ReconSettings& settings) const;
  void fill(VkCommandBuffer cmd, std::uint32_t word) const;

  const gpu::Buffer& direct(int eye, int parity) const { return eyes_[eye].direct[parity]; }
  const gpu::Buffer& indirect(int eye, int parity) const { return eyes_[eye].indirect[parity]; }
  const gpu::Buffer& position(int eye, int parity) const { return eyes_[eye].pos[parity]; }
  const gpu::Buffer& normal(int eye, int parity) const { return eyes_[eye].nrm[parity]; }
  const gpu::Buffer& tap_index(int eye) const { return eyes_[eye].tap_idx; }
  const gpu::Buffer& tap_weight(int eye) const { return eyes_[eye].tap_w; }
  // Frames since the history was rejected for coarse cells (float per cell; 0: none recent).
  const gpu::Buffer& restart(int eye, int parity) const { return eyes_[eye].restart[parity]; }
  // The first hits' albedo, accumulated with the direct light's history weights: its
  // jittered samples' mean is the texture's box filter over the cell (re-modulation, TAA).
  const gpu::Buffer& albedo(int eye, int parity) const { return eyes_[eye].albedo[parity]; }

 private:
  struct Eye {
    std::uint32_t cells = 0;
    const gpu::Buffer* live = nullptr;  // EyeGrid::live
    gpu::Buffer direct[2], indirect[2], pos[2], nrm[2], restart[2], albedo[2], tap_idx, tap_w;
    gpu::DescriptorSet set[2];
  };
  gpu::ComputePipeline kernel_;
  std::vector<Eye> eyes_;
};

class StereoGather {
 public:
  StereoGather(gpu::Context& ctx, std::span<const EyeGrid> eyes, const Accumulation& acc);
  // `share`: gather the other eye's indirect diffuse (else z = own direct + indirect). With
  // the BMFR denoiser it also flags the cells on a surface edge, which the fit leaves out.
  void record(VkCommandBuffer cmd, int parity, bool share, const ReconSettings& settings) const;
  void fill(VkCommandBuffer cmd, std::uint32_t word) const;

  const gpu::Buffer& shared(int eye) const { return eyes_[eye].shared; }
  const gpu::Buffer& z(int eye) const { return eyes_[eye].z; }
  const gpu::Buffer& edge(int eye) const { return eyes_[eye].edge; }  // uint per cell, 1: on a surface edge

 private:
  struct Eye {
    std::uint32_t cells = 0;
    const gpu::Buffer* live = nullptr;  // EyeGrid::live
    gpu::Buffer shared, z, edge;
    gpu::DescriptorSet set[2];
  };
  gpu::ComputePipeline kernel_;
  std::vector<Eye> eyes_;
};

class Bmfr {
 public:
  // `materials`: the scene's material table (cells without a diffuse lobe are not fitted).
  Bmfr(gpu::Context& ctx, std::span<const EyeGrid> eyes, const Accumulation& acc, const StereoGather& gather,
       const gpu::Buffer& materials, BmfrPrecision precision);
  void record(VkCommandBuffer cmd, int parity, std::uint32_t frame, glm::ivec2 offset, float noise) const;
  void fill(VkCommandBuffer cmd, std::uint32_t word) const;

  const gpu::Buffer& fitted(int eye) const { return eyes_[eye].fitted; }
  const gpu::Buffer& excess(int eye) const { return eyes_[eye].excess; }

 private:
  struct Eye {
    BmfrGrid grid;
    gpu::Buffer fitted, excess;
    gpu::DescriptorSet set[2];
  };
  BmfrFit fit_;
  std::vector<Eye> eyes_;
};

class PostTaa {
 public:
  // `bmfr`: the fitted input, or nullptr when BMFR is off (Phase III then filters z).
  // `final_albedo`: also write the albedo the output holds (final_albedo(); the resolve's
  // pixel albedo needs it), two more buffers of the grid's size per eye.
  PostTaa(gpu::Context& ctx, std::span<const EyeGrid> eyes, const Accumulation& acc, const StereoGather& gather,
          const Bmfr* bmfr, bool final_albedo = false);
  void record(VkCommandBuffer cmd, int parity, bool history, const ReconSettings& settings) const;
  // The two halves of record (Phase III, then TAA), each followed by its barrier; for timing.
  void record_post(VkCommandBuffer cmd, int parity, bool history, const ReconSettings& settings) const;
  void record_taa(VkCommandBuffer cmd, int parity, bool history, const ReconSettings& settings) const;
  void fill(VkCommandBuffer cmd, std::uint32_t word) const;

  // Remodulated output in grid space (.w = 1 where a sample exists).
  const gpu::Buffer& final_color(int eye, int parity) const { return eyes_[eye].final_[parity]; }
  // The albedo the output holds: the re-modulation's, blended with the history's as the colour
  // (one cell without final_albedo at construction).
  const gpu::Buffer& final_albedo(int eye, int parity) const { return eyes_[eye].final_albedo[parity]; }

 private:
  struct Eye {
    std::uint32_t cells = 0;
    const gpu::Buffer* live = nullptr;  // EyeGrid::live
    // post: accumulated fit (history); sum: + excess + direct
    gpu::Buffer post[2], sum, final_[2], final_albedo[2];
    gpu::DescriptorSet post_set[2], taa_set[2];
  };
  gpu::ComputePipeline post_, taa_;
  std::vector<Eye> eyes_;
};

class Resolve {
 public:
  // `post`: the albedo its output holds, which the display pixels' own replaces near the gaze.
  Resolve(gpu::Context& ctx, std::span<const EyeGrid> eyes, const Accumulation& acc, const PostTaa& post);
  // Copies a grid image into level 0 (transfer; the caller orders its writes before).
  void record_copy(VkCommandBuffer cmd, std::span<const gpu::Buffer* const> grid_images) const;
  // Optional blur of level 0 in grid space, mips from level 0, resolve, optional blur: into
  // the screen buffers; with set_depth_output(true) the resample also writes the depth of the
  // nearest sample per display pixel from the positions of `parity`. The kernels are also
  // recorded one by one (per-kernel timestamps). The peripheral blur runs in grid space on angular polar grids
  // (record_grid_blur, before the mips) and on the display for the others (record_blur).
  void record_resolve(VkCommandBuffer cmd, int parity, bool blur, const ReconSettings& settings) const;
  void record_grid_blur(VkCommandBuffer cmd, const ReconSettings& settings) const;
  void record_mips(VkCommandBuffer cmd) const;
  // grid_coords: each pixel's grid coordinate (u, t, LOD, 0) instead of its colour (tests);
  // settings.lattice_blur: the lattice's reconstruction of wide polar cells.
  void record_resample(VkCommandBuffer cmd, int parity, const ReconSettings& settings, bool grid_coords = false) const;
  // Whether the resample writes the display depth (depth()); off at first: a texel read, a
  // transform and a store per pixel that only depth compositing needs.
  void set_depth_output(bool on) { depth_output_ = on; }
  // This frame's window of the eye's EyeGrid::primary (none at first, and for an eye without one).
  void set_detail(int eye, const DetailWindow& window);
  bool depth_output() const { return depth_output_; }
  void record_blur(VkCommandBuffer cmd, const ReconSettings& settings) const;
  // The temporal error of the screen images on the device (shaders/recon_temporal.comp):
  // keeps each eye's luminance for the next call and, with `accumulate` (a previous image
  // exists), adds |Y - Y_previous| to running sums that temporal_abs_luma_sum() reads.
  void record_temporal(VkCommandBuffer cmd, bool accumulate) const;
  // Σ over pixels and accumulated frames of |Y - Y_previous| (a small download).
  double temporal_abs_luma_sum(int eye) const;
  void fill(VkCommandBuffer cmd, std::uint32_t word) const;

  gpu::Buffer& level0(int eye) { return eyes_[eye].mips; }  // for a given grid image
  const gpu::Buffer& screen(int eye) const { return eyes_[eye].screen_a; }
  gpu::Buffer& screen(int eye) { return eyes_[eye].screen_a; }  // for a given display image
  const gpu::Buffer& depth(int eye) const { return eyes_[eye].depth; }

 private:
  struct Eye {
    std::uint32_t cells = 0, width = 0, height = 0, padded_columns = 0, levels = 1;
    bool polar = true;
    double max_pixels_per_deg = 0;
    const GridMapping* mapping = nullptr;  // EyeGrid::mapping
    std::vector<std::uint32_t> level_rows, level_offset;
    DetailWindow detail;
    bool has_primary = false;
    gpu::Buffer mips, offsets, screen_a, screen_b, depth, grid_tmp, prev_luma, temporal_sums, no_primary;
    gpu::DescriptorSet mip_set, resolve_set[2], blur_h, blur_v, grid_blur_rho, grid_blur_phi, temporal_set;
  };
  std::uint32_t max_levels() const;
  gpu::ComputePipeline mip_, resolve_, blur_, grid_blur_, temporal_;
  std::vector<Eye> eyes_;
  bool depth_output_ = false;
};

}  // namespace fovea::reconstruct
