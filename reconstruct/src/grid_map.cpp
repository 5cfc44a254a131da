#include "fovea/reconstruct/grid_map.hpp"

#include <algorithm>
#include <cstring>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include "buffers.hpp"

namespace fovea::reconstruct {

using shaders::GridColumn;
using shaders::ReconGrid;

shaders::ReconGrid recon_grid(const core::SampleDistribution& d, const core::Pose& pose, std::uint32_t table_offset) {
  shaders::ReconGrid r{};
  r.g = d.gpu_params();
  // World-to-view rotation = transpose of the view-to-world rotation: its rows are the
  // view axes in world space.
  const glm::dmat3 v2w = glm::mat3_cast(pose.orientation);
  const glm::dvec3 x = v2w[0], y = v2w[1], z = v2w[2];
  r.w2v0_x = float(x.x), r.w2v0_y = float(x.y), r.w2v0_z = float(x.z);
  r.w2v1_x = float(y.x), r.w2v1_y = float(y.y), r.w2v1_z = float(y.z);
  r.w2v2_x = float(z.x), r.w2v2_y = float(z.y), r.w2v2_z = float(z.z);
  r.eye_x = float(pose.position.x), r.eye_y = float(pose.position.y), r.eye_z = float(pose.position.z);
  r.table_offset = table_offset;
  r.valid = 1;
  return r;
}

namespace {
std::uint32_t table_len(const core::SampleDistribution& d) {
  return std::max<std::uint32_t>(1, std::uint32_t(d.column_table().size()));
}
// The distribution's column table padded (or cut) to `len` entries.
void append_table(std::vector<GridColumn>& out, std::vector<GridColumn> t, std::uint32_t len) {
  t.resize(len, GridColumn{});
  out.insert(out.end(), t.begin(), t.end());
}
}  // namespace

GridMapping::GridMapping(gpu::Context& ctx, const core::SampleDistribution& own, const core::SampleDistribution* other)
    : own_(&own),
      other_(other),
      table_len_(table_len(own)),
      other_table_len_(other ? table_len(*other) : table_len(own)),
      maps_(storage(ctx, 3 * sizeof(ReconGrid), "recon.maps", gpu::Memory::HostVisible)),
      tables_(gpu::Buffer(ctx, {.size = VkDeviceSize(2 * table_len_ + other_table_len_) * sizeof(GridColumn),
                                .memory = gpu::Memory::HostVisible, .name = "recon.tables",
                                .texel_format = VK_FORMAT_R32G32B32A32_SFLOAT})) {}

void GridMapping::write(const core::Pose& own_pose, const core::Pose* other_pose) {
  ReconGrid m[3] = {recon_grid(*own_, own_pose, 0), prev_, ReconGrid{}};
  m[1].table_offset = table_len_;
  if (other_ && other_pose) m[2] = recon_grid(*other_, *other_pose, 2 * table_len_);
  std::memcpy(maps_.mapped().data(), m, sizeof(m));
  std::vector<GridColumn> t;
  append_table(t, own_->column_table(), table_len_);
  append_table(t, prev_table_, table_len_);
  if (other_ && other_pose) append_table(t, other_->column_table(), other_table_len_);
  std::memcpy(tables_.mapped().data(), t.data(), t.size() * sizeof(GridColumn));
}

void GridMapping::advance(const core::Pose& own_pose) {
  prev_ = recon_grid(*own_, own_pose, 0);
  prev_table_ = own_->column_table();
}

}  // namespace fovea::reconstruct
