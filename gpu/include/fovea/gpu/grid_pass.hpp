#pragma once
// GPU grid generation: writes one shaders::GridSample per cell of a sample distribution's
// padded grid (row-major, index = row * padded_columns + column) for its current frame.
// The CPU builds the per-frame uniforms and column table (core::SampleDistribution);
// the shader (shaders/grid_generate.comp) evaluates the mapping per cell. It also lists the
// tiles with a live cell (one with a sample) and those whose cells lost their sample
// (live_cells.h), with the indirect dispatches over them, so that the per-cell kernels start
// no workgroup for a tile without a sample (docs/renderer.md, "Live cells").
#include <cstdint>
#include <span>

#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"

namespace fovea::core {
class SampleDistribution;
}

namespace fovea::gpu {

class GridPass {
 public:
  // `cells`: the list's capacity to start with (it grows with the grids prepared, and
  // live_tiles() then is a new buffer). Cells are counted with subgroup ballots where the
  // device has them; `ballot = false` takes the variant for devices without (atomics per
  // cell) on any device, for tests.
  explicit GridPass(Context& ctx, std::uint32_t cells = 0, bool ballot = true);

  // Bytes needed for the samples of `d`'s padded grid.
  static VkDeviceSize samples_bytes(const core::SampleDistribution& d);

  // Uploads the frame's parameters (call outside command recording, before record()).
  // `hidden_mask`: optional bitmask of hidden view pixels in core::ViewMask's layout (rows of
  // ceil(W / 32) words, bit x & 31 of word y·ceil(W / 32) + x / 32), empty if none.
  void prepare(const core::SampleDistribution& d, std::span<const std::uint32_t> hidden_mask = {});
  // Records the dispatches writing into `samples` (at least samples_bytes(d) bytes) and the
  // live-tile list. Order later reads of either with compute_to_indirect.
  void record(VkCommandBuffer cmd, const Buffer& samples);
  // prepare + record in one submission, waiting for completion.
  void generate(const core::SampleDistribution& d, const Buffer& samples,
                std::span<const std::uint32_t> hidden_mask = {});

  // Cells of the last recorded dispatch, counted by the shader: traced (flags 0) and those
  // only the hidden mask skipped (flags kCellHidden). Valid once its submission completed.
  // reset: cells without a sample that had one in either of the two frames before.
  struct Counts {
    std::int64_t traced = 0, hidden = 0, reset = 0;
  };
  Counts counts() const;

  // The live-tile list of the last recorded dispatch (live_cells.h): header, then the tiles;
  // a storage buffer and the indirect dispatches' arguments.
  const Buffer& live_tiles() const { return list_; }
  // The next record() treats every cell as having had a sample in the two frames before, so
  // that those without one now are listed as reset (after the per-cell buffers were
  // overwritten, e.g. filled).
  void reset_history() { history_fresh_ = true; }

 private:
  Context* ctx_;
  void reserve(std::uint32_t cells);

  ComputePipeline pipeline_, list_pipeline_;
  Buffer params_;
  Buffer columns_;
  Buffer mask_;
  Buffer counts_;   // shaders::GridCounts, host-visible
  Buffer list_;        // header + capacity tiles
  Buffer history_;     // a word per cell: kLiveAllBefore's bits
  Buffer tile_state_;  // a word per tile, zero between frames (grid_generate.comp, grid_live_list.comp)
  DescriptorSet set_, list_set_;
  VkBuffer bound_samples_ = VK_NULL_HANDLE;
  std::uint32_t padded_columns_ = 0, padded_rows_ = 0, capacity_ = 0;
  bool history_fresh_ = true;
};

}  // namespace fovea::gpu
