#pragma once
// GPU grid generation: writes one shaders::GridSample per cell of a sample distribution's
// padded grid (row-major, index = row * padded_columns + column) for its current frame.
// The CPU builds the per-frame uniforms and column table (core::SampleDistribution);
// the shader (shaders/grid_generate.comp) evaluates the mapping per cell.
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
  explicit GridPass(Context& ctx);

  // Bytes needed for the samples of `d`'s padded grid.
  static VkDeviceSize samples_bytes(const core::SampleDistribution& d);

  // Uploads the frame's parameters (call outside command recording, before record()).
  // `hidden_mask`: optional bitmask of hidden view pixels in core::ViewMask's layout (rows of
  // ceil(W / 32) words, bit x & 31 of word y·ceil(W / 32) + x / 32), empty if none.
  void prepare(const core::SampleDistribution& d, std::span<const std::uint32_t> hidden_mask = {});
  // Records the dispatch writing into `samples` (at least samples_bytes(d) bytes).
  void record(VkCommandBuffer cmd, const Buffer& samples);
  // prepare + record in one submission, waiting for completion.
  void generate(const core::SampleDistribution& d, const Buffer& samples,
                std::span<const std::uint32_t> hidden_mask = {});

  // Cells of the last recorded dispatch, counted by the shader: traced (flags 0) and those
  // only the hidden mask skipped (flags kCellHidden). Valid once its submission completed.
  struct Counts {
    std::int64_t traced = 0, hidden = 0;
  };
  Counts counts() const;

 private:
  Context* ctx_;
  ComputePipeline pipeline_;
  Buffer params_;
  Buffer columns_;
  Buffer mask_;
  Buffer counts_;  // two uints, host-visible: traced, hidden
  DescriptorSet set_;
  VkBuffer bound_samples_ = VK_NULL_HANDLE;
  std::uint32_t padded_columns_ = 0, padded_rows_ = 0;
};

}  // namespace fovea::gpu
