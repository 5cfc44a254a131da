#pragma once
// The per-frame grid mappings the reconstruction kernels read (shaders/include/fovea/shaders/
// recon_grid.h): per eye, ReconGrid[3] = this frame, the previous frame (reprojection), the
// other eye (stereo gather), their column tables and radius lookup tables, in mapped buffers
// (gpu::Memory::Upload: device memory where the device can map it). The host reads its own
// copies of what it wrote, never the buffers.
#include <cstdint>
#include <span>
#include <vector>

#include "fovea/core/distribution.hpp"
#include "fovea/core/view.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/shaders/recon_grid.h"

namespace fovea::reconstruct {

// The grid mapping of `d`'s current frame seen from `eye_pose` (world), for the shaders;
// its column table is expected at `table_offset` in the bound table buffer.
shaders::ReconGrid recon_grid(const core::SampleDistribution& d, const core::Pose& eye_pose,
                              std::uint32_t table_offset);

// Radius -> column lookup table of a polar column table (recon_map.h, rg_column_range):
// kReconRadiusLutEntries entries; entry k <= kReconRadiusLutSize holds the last column
// whose r0 is <= (k - 0.5) / scale (column 0 when none), the one after it the last column;
// scale = kReconRadiusLutSize / the last column's outer radius. Empty for an empty table.
struct RadiusLut {
  float scale = 0;
  std::vector<std::uint32_t> entries;
};
RadiusLut radius_lut(std::span<const shaders::GridColumn> table);

class GridMapping {
 public:
  // `own` is the eye's distribution, `other` the other eye's (nullptr: one eye).
  GridMapping(gpu::Context& ctx, const core::SampleDistribution& own, const core::SampleDistribution* other);

  // Uploads this frame's mapping of both distributions (their current frame) with the poses.
  void write(const core::Pose& own_pose, const core::Pose* other_pose);
  // After a frame: this frame's mapping becomes the previous one.
  void advance(const core::Pose& own_pose);
  // Whether the last write's mapping is the previous one's but for the cells' jitter (same
  // layout, pose and column table): every cell's history is then its own cell's, and Phase I
  // takes it without reprojecting (shaders/recon_accumulate.comp).
  bool unmoved() const { return unmoved_; }

  // This frame's mapping and column table, as the last write uploaded them.
  const shaders::ReconGrid& current() const { return current_; }
  std::span<const shaders::GridColumn> current_table() const { return current_table_; }

  const gpu::Buffer& maps() const { return maps_; }
  const gpu::Buffer& tables() const { return tables_; }
  // R32_UINT texels: the radius lookup table of each polar mapping, at its lut_offset.
  const gpu::Buffer& luts() const { return luts_; }

 private:
  const core::SampleDistribution* own_;
  const core::SampleDistribution* other_;
  std::uint32_t table_len_ = 1, other_table_len_ = 1;
  shaders::ReconGrid prev_{}, current_{};
  std::vector<shaders::GridColumn> prev_table_, current_table_;
  bool unmoved_ = false;
  gpu::Buffer maps_, tables_, luts_;
};

}  // namespace fovea::reconstruct
