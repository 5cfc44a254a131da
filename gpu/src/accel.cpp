#include "fovea/gpu/accel.hpp"

#include <algorithm>
#include <utility>

#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/error.hpp"

namespace fovea::gpu {
namespace {

// The loader does not export extension commands: fetch them from the device.
template <class F>
F device_fn(VkDevice dev, const char* name) {
  auto f = reinterpret_cast<F>(vkGetDeviceProcAddr(dev, name));
  if (f == nullptr) throw std::runtime_error(std::string("Vulkan device lacks ") + name);
  return f;
}

struct AccelFns {
  PFN_vkGetAccelerationStructureBuildSizesKHR sizes;
  PFN_vkCreateAccelerationStructureKHR create;
  PFN_vkCmdBuildAccelerationStructuresKHR build;
  PFN_vkGetAccelerationStructureDeviceAddressKHR address;
  explicit AccelFns(VkDevice d)
      : sizes(device_fn<PFN_vkGetAccelerationStructureBuildSizesKHR>(d, "vkGetAccelerationStructureBuildSizesKHR")),
        create(device_fn<PFN_vkCreateAccelerationStructureKHR>(d, "vkCreateAccelerationStructureKHR")),
        build(device_fn<PFN_vkCmdBuildAccelerationStructuresKHR>(d, "vkCmdBuildAccelerationStructuresKHR")),
        address(device_fn<PFN_vkGetAccelerationStructureDeviceAddressKHR>(
            d, "vkGetAccelerationStructureDeviceAddressKHR")) {}
};

Buffer input_buffer(Context& ctx, std::span<const std::byte> data, const char* name) {
  Buffer b(ctx, {data.size(), BufferUsage::DeviceAddress | BufferUsage::BuildInput, Memory::DeviceLocal, name});
  b.upload_bytes(data);
  return b;
}

// Sizes `info` for `count` primitives, creates the structure in a fresh storage buffer and
// points info.dstAccelerationStructure at it.
VkAccelerationStructureKHR create_level(Context& ctx, const AccelFns& fn, VkAccelerationStructureBuildGeometryInfoKHR& info,
                                        std::uint32_t count, Buffer& storage, VkDeviceSize& scratch_bytes,
                                        const char* name) {
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  fn.sizes(ctx.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &count, &sizes);
  storage = Buffer(ctx, {sizes.accelerationStructureSize, BufferUsage::AccelerationStructure | BufferUsage::DeviceAddress,
                         Memory::DeviceLocal, name});
  VkAccelerationStructureCreateInfoKHR ci{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  ci.buffer = storage.handle();
  ci.size = sizes.accelerationStructureSize;
  ci.type = info.type;
  VkAccelerationStructureKHR as = VK_NULL_HANDLE;
  check(fn.create(ctx.device(), &ci, nullptr, &as), "vkCreateAccelerationStructureKHR");
  ctx.set_name(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR, reinterpret_cast<std::uint64_t>(as), name);
  info.dstAccelerationStructure = as;
  scratch_bytes = std::max(scratch_bytes, sizes.buildScratchSize);
  return as;
}

}  // namespace

TriangleAccel::TriangleAccel(Context& ctx, std::span<const float> vertices) : device_(ctx.device()) {
  if (!ctx.features().ray_query)
    throw core::InputError("acceleration structure: the Vulkan device '" + ctx.info().name +
                           "' does not offer ray queries (VK_KHR_acceleration_structure + VK_KHR_ray_query)");
  if (vertices.empty() || vertices.size() % 9 != 0)
    throw core::InputError("acceleration structure: expected 9 floats per triangle, got " +
                           std::to_string(vertices.size()));
  const auto triangles = static_cast<std::uint32_t>(vertices.size() / 9);
  const AccelFns fn(ctx.device());
  destroy_ = device_fn<PFN_vkDestroyAccelerationStructureKHR>(device_, "vkDestroyAccelerationStructureKHR");
  try {
    const Buffer vbuf = input_buffer(ctx, std::as_bytes(vertices), "as.vertices");
    VkAccelerationStructureGeometryKHR tri{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    tri.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    tri.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    tri.geometry.triangles.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    tri.geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    tri.geometry.triangles.vertexData.deviceAddress = vbuf.device_address();
    tri.geometry.triangles.vertexStride = 3 * sizeof(float);
    tri.geometry.triangles.maxVertex = 3 * triangles - 1;
    tri.geometry.triangles.indexType = VK_INDEX_TYPE_NONE_KHR;
    VkAccelerationStructureBuildGeometryInfoKHR bottom{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
    bottom.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    bottom.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
    bottom.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    bottom.geometryCount = 1;
    bottom.pGeometries = &tri;
    VkDeviceSize scratch_bytes = 0;
    bottom_ = create_level(ctx, fn, bottom, triangles, bottom_storage_, scratch_bytes, "as.bottom");

    VkAccelerationStructureDeviceAddressInfoKHR ai{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
    ai.accelerationStructure = bottom_;
    VkAccelerationStructureInstanceKHR instance{};
    for (int i = 0; i < 3; ++i) instance.transform.matrix[i][i] = 1.0f;
    instance.mask = 0xFF;
    instance.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR | VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR;
    instance.accelerationStructureReference = fn.address(ctx.device(), &ai);
    const Buffer ibuf = input_buffer(ctx, std::as_bytes(std::span(&instance, 1)), "as.instances");
    VkAccelerationStructureGeometryKHR inst{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    inst.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
    inst.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    inst.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
    inst.geometry.instances.data.deviceAddress = ibuf.device_address();
    VkAccelerationStructureBuildGeometryInfoKHR top = bottom;
    top.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
    top.pGeometries = &inst;
    top_ = create_level(ctx, fn, top, 1, top_storage_, scratch_bytes, "as.top");

    // One scratch buffer for both builds, ordered by the barrier between them.
    const VkDeviceSize align = std::max<VkDeviceSize>(ctx.features().as_scratch_alignment, 1);
    const Buffer scratch(ctx, {scratch_bytes + align, BufferUsage::Storage | BufferUsage::DeviceAddress,
                               Memory::DeviceLocal, "as.scratch"});
    const VkDeviceAddress base = (scratch.device_address() + align - 1) / align * align;
    bottom.scratchData.deviceAddress = base;
    top.scratchData.deviceAddress = base;
    const VkAccelerationStructureBuildRangeInfoKHR bottom_range{triangles, 0, 0, 0}, top_range{1, 0, 0, 0};
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      const VkAccelerationStructureBuildRangeInfoKHR* r = &bottom_range;
      fn.build(cmd, 1, &bottom, &r);
      const Access build{VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                         VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR};
      barrier(cmd, build, build);
      r = &top_range;
      fn.build(cmd, 1, &top, &r);
    });
  } catch (...) {
    release();
    throw;
  }
}

TriangleAccel::~TriangleAccel() { release(); }

void TriangleAccel::release() {
  if (top_ != VK_NULL_HANDLE) destroy_(device_, top_, nullptr);
  if (bottom_ != VK_NULL_HANDLE) destroy_(device_, bottom_, nullptr);
  top_ = bottom_ = VK_NULL_HANDLE;
}

TriangleAccel::TriangleAccel(TriangleAccel&& o) noexcept
    : device_(o.device_),
      destroy_(o.destroy_),
      bottom_storage_(std::move(o.bottom_storage_)),
      top_storage_(std::move(o.top_storage_)),
      bottom_(std::exchange(o.bottom_, VK_NULL_HANDLE)),
      top_(std::exchange(o.top_, VK_NULL_HANDLE)) {}

TriangleAccel& TriangleAccel::operator=(TriangleAccel&& o) noexcept {
  if (this != &o) {
    release();  // the structures go before the storage they live in
    device_ = o.device_;
    destroy_ = o.destroy_;
    bottom_ = std::exchange(o.bottom_, VK_NULL_HANDLE);
    top_ = std::exchange(o.top_, VK_NULL_HANDLE);
    bottom_storage_ = std::move(o.bottom_storage_);
    top_storage_ = std::move(o.top_storage_);
  }
  return *this;
}

}  // namespace fovea::gpu
