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
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "fovea/gpu/buffer.hpp"
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

inline constexpr std::uint32_t kBmfrDefaultWorkgroup = 8;

struct BmfrOptions {
  BmfrPrecision precision = BmfrPrecision::Fp32;
  std::uint32_t workgroup = 0;  // invocations per block: 8..512 dividing 1024; 0: default (8)
};

class BmfrFit {
 public:
  explicit BmfrFit(gpu::Context& ctx, const BmfrOptions& options = {});
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
  std::uint32_t workgroup_;
  gpu::ComputePipeline pipeline_;
};

// BMFR's 16 static block-grid displacements (cells, in [0, 32)²), uniformly spread over all
// offsets: frame f uses entry f % 16.
glm::ivec2 bmfr_block_offset(std::uint32_t frame);

}  // namespace fovea::reconstruct
