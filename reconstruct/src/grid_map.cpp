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

// Whether mappings a and b lay their cells out alike from the same pose: equal but for the
// jitter, the frame (which only picks a linear fall-off's killed cells, not where cells lie)
// and where their tables are bound. Bytewise, so a NaN or a signed zero counts as a change.
bool same_layout(ReconGrid a, ReconGrid b) {
  for (ReconGrid* m : {&a, &b}) {
    m->g.jitter_u = m->g.jitter_v = 0;
    m->g.frame = 0;
    m->table_offset = m->lut_offset = 0;
    m->lut_scale = 0;
  }
  return std::memcmp(&a, &b, sizeof(ReconGrid)) == 0;
}

bool same_table(const std::vector<GridColumn>& a, const std::vector<GridColumn>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(GridColumn)) == 0);
}

// Mapping m's radius lookup table from its column table, at slot `slot` of `luts`; none
// (lut_scale 0: the shaders search the whole table) for a Cartesian or absent mapping.
void put_lut(ReconGrid& m, const std::vector<GridColumn>& table, std::uint32_t slot, std::uint32_t* luts) {
  m.lut_offset = slot * shaders::kReconRadiusLutEntries;
  m.lut_scale = 0;
  if (!m.valid || m.g.family == shaders::kFamilyCartesian) return;
  const RadiusLut lut = radius_lut(std::span(table).first(std::min<std::size_t>(table.size(), m.g.columns)));
  if (lut.entries.empty()) return;
  std::copy(lut.entries.begin(), lut.entries.end(), luts + m.lut_offset);
  m.lut_scale = lut.scale;
}
}  // namespace

RadiusLut radius_lut(std::span<const GridColumn> table) {
  RadiusLut lut;
  if (table.empty()) return lut;
  constexpr std::uint32_t size = shaders::kReconRadiusLutSize;
  const auto last = std::uint32_t(table.size() - 1);
  lut.scale = float(size) / std::max(table[last].r1, 1e-6f);
  lut.entries.resize(shaders::kReconRadiusLutEntries);
  // The bins' lower bounds rise with k and the columns' r0 with the column: one walk.
  std::uint32_t c = 0;
  for (std::uint32_t k = 0; k <= size; ++k) {
    const double bound = (double(k) - 0.5) / double(lut.scale);
    while (c < last && double(table[c + 1].r0) <= bound) ++c;
    lut.entries[k] = c;
  }
  lut.entries[size + 1] = last;
  return lut;
}

GridMapping::GridMapping(gpu::Context& ctx, const core::SampleDistribution& own, const core::SampleDistribution* other)
    : own_(&own),
      other_(other),
      table_len_(table_len(own)),
      other_table_len_(other ? table_len(*other) : table_len(own)),
      maps_(storage(ctx, 3 * sizeof(ReconGrid), "recon.maps", gpu::Memory::Upload)),
      tables_(gpu::Buffer(ctx, {.size = VkDeviceSize(2 * table_len_ + other_table_len_) * sizeof(GridColumn),
                                .memory = gpu::Memory::Upload, .name = "recon.tables",
                                .texel_format = VK_FORMAT_R32G32B32A32_SFLOAT})),
      luts_(gpu::Buffer(ctx, {.size = VkDeviceSize(3) * shaders::kReconRadiusLutEntries * sizeof(std::uint32_t),
                              .memory = gpu::Memory::Upload, .name = "recon.radius_luts",
                              .texel_format = VK_FORMAT_R32_UINT})) {}

void GridMapping::write(const core::Pose& own_pose, const core::Pose* other_pose) {
  ReconGrid m[3] = {recon_grid(*own_, own_pose, 0), prev_, ReconGrid{}};
  m[1].table_offset = table_len_;
  unmoved_ = prev_.valid && same_layout(m[0], prev_) && same_table(own_->column_table(), prev_table_);
  if (other_ && other_pose) m[2] = recon_grid(*other_, *other_pose, 2 * table_len_);
  auto* luts = reinterpret_cast<std::uint32_t*>(luts_.mapped().data());
  put_lut(m[0], own_->column_table(), 0, luts);
  put_lut(m[1], prev_table_, 1, luts);
  if (other_ && other_pose) put_lut(m[2], other_->column_table(), 2, luts);
  std::memcpy(maps_.mapped().data(), m, sizeof(m));
  current_ = m[0];
  current_table_.clear();
  append_table(current_table_, own_->column_table(), table_len_);  // as the shaders see it
  std::vector<GridColumn> t = current_table_;
  append_table(t, prev_table_, table_len_);
  if (other_ && other_pose) append_table(t, other_->column_table(), other_table_len_);
  std::memcpy(tables_.mapped().data(), t.data(), t.size() * sizeof(GridColumn));
}

void GridMapping::advance(const core::Pose& own_pose) {
  prev_ = recon_grid(*own_, own_pose, 0);
  prev_table_ = own_->column_table();
}

}  // namespace fovea::reconstruct
