#pragma once
// Compute pipelines from the embedded SPIR-V (fovea::shaders::find), with their own
// pipeline layout: descriptor set layouts, one push-constant range, optional 32-bit
// specialization constants. The workgroup size is read from the SPIR-V (including
// local_size_*_id specialization), so dispatches can be given in threads. A device compiles
// each description once: pipelines made with the same description share its kernel.
#include <array>
#include <bit>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/handle.hpp"

namespace fovea::gpu {

// Value of `layout(constant_id = id) const ...` (int, uint, float or bool).
struct SpecConstant {
  std::uint32_t id = 0;
  std::uint32_t bits = 0;
  static SpecConstant u32(std::uint32_t id, std::uint32_t v) { return {id, v}; }
  static SpecConstant i32(std::uint32_t id, std::int32_t v) { return {id, std::bit_cast<std::uint32_t>(v)}; }
  static SpecConstant f32(std::uint32_t id, float v) { return {id, std::bit_cast<std::uint32_t>(v)}; }
  static SpecConstant boolean(std::uint32_t id, bool v) { return {id, v ? 1u : 0u}; }
};

struct ComputePipelineDesc {
  std::string shader;                      // embedded name, e.g. "pt_trace.comp.spv"
  std::vector<std::vector<Binding>> sets;  // sets[s][b]: type of `layout(set = s, binding = b)`
  std::uint32_t push_constant_bytes = 0;   // size of the push_constant block, multiple of 4
  std::vector<SpecConstant> specialization;
};

// The descriptor types the embedded `shader` declares in `set`, binding b at index b: for
// layouts that follow the shader (storage or texel buffer per binding). Throws
// core::InputError for an unknown shader or a binding number the set skips.
std::vector<Binding> declared_bindings(const std::string& shader, std::uint32_t set = 0);

// What a ComputePipeline binds: its layouts and the compiled pipeline. Made once per device
// and description and kept by the Context until it is released (creating a pipeline takes
// ~15 ms on lavapipe, and a frame pipeline has 15 of them).
struct CompiledKernel {
  std::vector<DescriptorSetLayout> set_layouts;
  DeviceHandle<VkPipelineLayout, vkDestroyPipelineLayout> layout;
  DeviceHandle<VkPipeline, vkDestroyPipeline> pipeline;
  std::array<std::uint32_t, 3> local_size{1, 1, 1};
};

class ComputePipeline {
 public:
  ComputePipeline() = default;
  // Throws core::InputError for an unknown shader name or an invalid description. The kernel
  // is the device's for this description (Context::kernel), compiled on first use.
  ComputePipeline(Context& ctx, const ComputePipelineDesc& desc);
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;
  ComputePipeline(ComputePipeline&&) = default;
  ComputePipeline& operator=(ComputePipeline&&) = default;

  VkPipeline handle() const { return kernel_ ? kernel_->pipeline.get() : VK_NULL_HANDLE; }
  VkPipelineLayout layout() const { return kernel_ ? kernel_->layout.get() : VK_NULL_HANDLE; }
  // Throws std::out_of_range for a set the layout does not have (any, for an empty pipeline).
  const DescriptorSetLayout& set_layout(std::size_t set) const;
  std::array<std::uint32_t, 3> workgroup_size() const {
    return kernel_ ? kernel_->local_size : std::array<std::uint32_t, 3>{1, 1, 1};
  }
  const std::string& shader() const { return shader_; }

  // Records: bind the pipeline and sets[i] as set i.
  void bind(VkCommandBuffer cmd, std::initializer_list<const DescriptorSet*> sets = {}) const;
  // Records: push constants; `bytes` must be push_constant_bytes long.
  void push_bytes(VkCommandBuffer cmd, std::span<const std::byte> bytes) const;
  template <class T>
  void push(VkCommandBuffer cmd, const T& constants) const {
    push_bytes(cmd, std::as_bytes(std::span(&constants, 1)));
  }
  // Records: vkCmdDispatch with enough workgroups to cover x * y * z threads (rounded up;
  // shaders must bounds-check). Throws core::InputError beyond the device's group limits.
  void dispatch(VkCommandBuffer cmd, std::uint32_t x, std::uint32_t y = 1, std::uint32_t z = 1) const;

  // Records a 1-D dispatch of `count` invocations for a shader that indexes them with
  // FOVEA_LINEAR_INVOCATION (shaders/include/fovea/shaders/common.h): more workgroups than the
  // device allows in x (maxComputeWorkGroupCount[0]: 65535 on lavapipe, so 4 M invocations
  // of 64) are folded into rows of groups, so a full-resolution grid of any preset dispatches
  // on any device. Rounded up like dispatch(); the shader bounds-checks.
  void dispatch_linear(VkCommandBuffer cmd, std::uint32_t count) const;
  // Records vkCmdDispatchIndirect with the arguments at `offset` in `args` (a buffer with
  // BufferUsage::Indirect, written by an earlier shader: order it with compute_to_indirect).
  // For counts a shader found, folded like dispatch_linear (live_cells.h).
  void dispatch_indirect(VkCommandBuffer cmd, const Buffer& args, VkDeviceSize offset) const;
  template <class T>
  void run_linear(VkCommandBuffer cmd, std::initializer_list<const DescriptorSet*> sets, const T& constants,
                  std::uint32_t count) const {
    bind(cmd, sets);
    push(cmd, constants);
    dispatch_linear(cmd, count);
  }

  // Bind, push and dispatch in one go.
  template <class T>
  void run(VkCommandBuffer cmd, std::initializer_list<const DescriptorSet*> sets, const T& constants,
           std::uint32_t x, std::uint32_t y = 1, std::uint32_t z = 1) const {
    bind(cmd, sets);
    push(cmd, constants);
    dispatch(cmd, x, y, z);
  }

 private:
  std::string shader_;
  std::uint32_t push_bytes_ = 0;
  std::array<std::uint32_t, 3> max_groups_{0, 0, 0};
  std::shared_ptr<const CompiledKernel> kernel_;
};

// Compute pipelines on a device Fovea does not own (the application's, in the API layer and
// the runtime), made through that device's own vkGetDeviceProcAddr: one descriptor set layout
// (set 0, checked against the shader's declarations like ComputePipeline's), one pipeline
// layout with one push-constant range, and one pipeline per specialisation. The caller owns
// the handles and destroys them with destroy_foreign_pipelines.
struct ForeignPipelineDesc {
  std::string shader;                      // embedded name
  std::vector<VkDescriptorType> bindings;  // binding b at index b (dynamic buffers allowed)
  std::uint32_t push_constant_bytes = 0;
  // One pipeline per entry: the values of constant_id 0, 1, ... (an empty list: one pipeline
  // without specialisation).
  std::vector<std::vector<std::uint32_t>> specializations;
};
struct ForeignPipelines {
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  std::vector<VkPipeline> pipelines;
};
// Throws core::InputError for a layout that does not match the shader, VulkanError for a
// failed call (nothing is left created then).
ForeignPipelines create_foreign_pipelines(VkDevice device, PFN_vkGetDeviceProcAddr get_device_proc,
                                          const ForeignPipelineDesc& desc);
void destroy_foreign_pipelines(VkDevice device, PFN_vkGetDeviceProcAddr get_device_proc, ForeignPipelines& p);

}  // namespace fovea::gpu
