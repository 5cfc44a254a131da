#pragma once
// BMFR Phase II on the GPU (shaders/recon_bmfr_fit.comp): per 32×32 block of a padded grid,
// the regression of the demodulated input z on the features [1, n, w, w²] (least squares via
// the Cholesky factor of the block's Gram matrix) and the weighted sum. Inputs per cell
// (vec4): vpos (world position, .w material; < 0 = no surface), vnrm (normal, .w the distance
// to the eye), z (rgb, .w sample count); outputs: fitted (rgb, .w = z's count) and excess
// (rgb: the part of z above its block's outlier bound, which the fit did not see; the
// estimate is fitted + excess). On polar grids the blocks wrap in φ:
// rows are read modulo each column's row count (the grid's column table). Cells whose
// material (shaders::PtMaterial of the scene's table, indexed by vpos.w) has no diffuse lobe
// stay out of the regression and keep z: their indirect diffuse is zero by construction; so
// do the cells flagged as on a surface edge (edge, uint per cell; the stereo gather flags a
// cell with a 3×3 neighbour that the history's validity test would not take for the same
// surface), whose jittered history mixes both sides.
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/pipeline.hpp"

namespace fovea::reconstruct {

struct BmfrGrid {
  std::uint32_t padded_columns = 0, padded_rows = 0;  // multiples of 32
  // Polar grids: the logical columns, whose rows (shaders::GridColumn::rows of the bound
  // column table) are cyclic in φ; 0: a raster, no wrap.
  std::uint32_t columns = 0;
};

// Precision of the regression's features and input: fp32, or rounded to fp16 (the BMFR
// paper's storage type for them; w is scaled to [−1, 1] before squaring and z by its block
// maximum, so no value exceeds the fp16 range). Sums and the solve are fp32 in both.
enum class BmfrPrecision { Fp32, Fp16 };

// How a block's reductions combine the invocations' partial sums: each invocation's folded
// serially, or each subgroup's first (subgroup arithmetic), then the subgroups' serially.
enum class BmfrReduction { Serial, Subgroup };

// The fit's workgroup per block (invocations, each streaming 1024 / workgroup of the block's
// rows) and its reductions: a pure schedule choice, the same images up to fp32 summation order.
struct BmfrSchedule {
  std::uint32_t workgroup = 8;
  BmfrReduction reduction = BmfrReduction::Serial;
};

// The schedule for a device. A CPU device (lavapipe runs a workgroup on one thread, its
// invocations as SIMD lanes, and a barrier switches between groups of lanes): 8 invocations,
// serial folds (docs/reconstruction.md, "Workgroup design": fastest there, where subgroup
// arithmetic loops over the lanes). A GPU: 256 invocations, so a block fills whole
// subgroups (8 of 32 lanes left 3/4 of each warp idle and gave a block's 1024 rows to 8
// threads), with subgroup reductions where the device has subgroup arithmetic.
BmfrSchedule bmfr_schedule(const gpu::DeviceInfo& device);

struct BmfrOptions {
  BmfrPrecision precision = BmfrPrecision::Fp32;
  // The schedule; none: bmfr_schedule of the context's device. Its workgroup divides 1024
  // and is 8..512; Subgroup needs subgroup arithmetic.
  std::optional<BmfrSchedule> schedule;
};

class BmfrFit {
 public:
  explicit BmfrFit(gpu::Context& ctx, const BmfrOptions& options = {});
  BmfrSchedule schedule() const { return schedule_; }
  // `columns`: the grid's column table (shaders::GridColumn, this frame's first);
  // `materials`: the scene's shaders::PtMaterial table (material codes beyond it count as diffuse);
  // `edge`: uint per cell, non-zero for a cell on a surface edge. vpos, vnrm and z are read
  // as texels and need BufferDesc::texel_format R32G32B32A32_SFLOAT, edge R32_UINT.
  gpu::DescriptorSet bind(const gpu::Buffer& vpos, const gpu::Buffer& vnrm, const gpu::Buffer& z,
                          const gpu::Buffer& fitted, const gpu::Buffer& columns, const gpu::Buffer& materials,
                          const gpu::Buffer& excess, const gpu::Buffer& edge) const;
  // Records the fit; `offset` is the block-grid displacement in [0, 32)².
  void record(VkCommandBuffer cmd, const gpu::DescriptorSet& set, BmfrGrid grid, std::uint32_t frame,
              glm::ivec2 offset, float noise) const;
  // Upload, fit, download in one submission (tests, tools): fitted + excess. `rows`: rows per column of a
  // polar grid (grid.columns entries) or empty for a raster; `metal`: per material code,
  // whether it has no diffuse lobe (codes beyond the list: diffuse); `edge`: per cell, non-zero
  // on a surface edge (empty: none).
  std::vector<glm::vec4> fit(BmfrGrid grid, const std::vector<glm::vec4>& vpos, const std::vector<glm::vec4>& vnrm,
                             const std::vector<glm::vec4>& z, std::uint32_t frame = 0, glm::ivec2 offset = {0, 0},
                             float noise = 0.01f, const std::vector<std::uint32_t>& rows = {},
                             const std::vector<bool>& metal = {},
                             const std::vector<std::uint32_t>& edge = {}) const;

 private:
  gpu::Context* ctx_;
  BmfrSchedule schedule_;
  gpu::ComputePipeline pipeline_;
};

// BMFR's 16 static block-grid displacements (cells, in [0, 32)²), uniformly spread over all
// offsets: frame f uses entry f % 16.
glm::ivec2 bmfr_block_offset(std::uint32_t frame);

}  // namespace fovea::reconstruct
