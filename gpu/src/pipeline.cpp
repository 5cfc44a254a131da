#include "fovea/gpu/pipeline.hpp"

#include <cstring>
#include <stdexcept>
#include <string>

#include "fovea/core/error.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/gpu/error.hpp"
#include "fovea/shaders/embedded.hpp"
#include "spirv.hpp"

namespace fovea::gpu {
namespace {

std::string known_shaders() {
  std::string s;
  for (std::string_view n : shaders::names()) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

// The layout must match the shader's declarations binding for binding: Vulkan leaves a
// mismatch undefined (validation reports only some), so a C++ list that drifted from the
// GLSL fails here, at start-up, naming the binding.
void check_bindings(const std::string& what, std::span<const std::uint32_t> words,
                    const std::vector<std::vector<Binding>>& sets) {
  const auto where = [](std::uint32_t set, std::uint32_t b) {
    return "set " + std::to_string(set) + " binding " + std::to_string(b);
  };
  std::vector<std::vector<bool>> declared(sets.size());
  for (std::size_t s = 0; s < sets.size(); ++s) declared[s].assign(sets[s].size(), false);
  for (const spirv::DeclaredBinding& d : spirv::descriptor_bindings(words)) {
    if (d.set >= sets.size() || d.binding >= sets[d.set].size())
      throw core::InputError(what + ": the shader declares a " + binding_name(d.type) + " at " +
                             where(d.set, d.binding) + ", which the layout does not have");
    if (sets[d.set][d.binding] != d.type)
      throw core::InputError(what + ": " + where(d.set, d.binding) + " is a " + binding_name(d.type) +
                             " in the shader but a " + binding_name(sets[d.set][d.binding]) + " in the layout");
    declared[d.set][d.binding] = true;
  }
  for (std::size_t s = 0; s < sets.size(); ++s)
    for (std::size_t b = 0; b < sets[s].size(); ++b)
      if (!declared[s][b])
        throw core::InputError(what + ": the layout has a " + binding_name(sets[s][b]) + " at " +
                               where(std::uint32_t(s), std::uint32_t(b)) + " that the shader does not declare");
}

// The embedded shader's SPIR-V words (copied: independent of the embedded arrays' alignment).
std::vector<std::uint32_t> spirv_words(const std::string& shader, const std::string& what) {
  const std::span<const std::uint8_t> bytes = shaders::find(shader);
  if (bytes.empty()) throw core::InputError(what + ": no such embedded shader; known: " + known_shaders());
  if (bytes.size() % 4 != 0) throw core::InputError(what + ": SPIR-V size is not a multiple of 4");
  std::vector<std::uint32_t> words(bytes.size() / 4);
  std::memcpy(words.data(), bytes.data(), bytes.size());
  return words;
}

}  // namespace

std::vector<Binding> declared_bindings(const std::string& shader, std::uint32_t set) {
  const std::string what = "gpu::declared_bindings '" + shader + "'";
  std::vector<Binding> out;
  for (const spirv::DeclaredBinding& d : spirv::descriptor_bindings(spirv_words(shader, what))) {
    if (d.set != set) continue;
    if (d.binding != out.size())
      throw core::InputError(what + ": set " + std::to_string(set) + " has no binding " + std::to_string(out.size()));
    out.push_back(d.type);
  }
  return out;
}

ComputePipeline::ComputePipeline(Context& ctx, const ComputePipelineDesc& desc)
    : shader_(desc.shader), push_bytes_(desc.push_constant_bytes) {
  const std::string what = "gpu::ComputePipeline '" + desc.shader + "'";
  const std::vector<std::uint32_t> words = spirv_words(desc.shader, what);
  if (desc.push_constant_bytes % 4 != 0 || desc.push_constant_bytes > ctx.limits().maxPushConstantsSize)
    throw core::InputError(what + ": push_constant_bytes " + std::to_string(desc.push_constant_bytes) +
                           " must be a multiple of 4 and at most " + std::to_string(ctx.limits().maxPushConstantsSize));
  local_size_ = spirv::workgroup_size(words, desc.specialization);
  for (int i = 0; i < 3; ++i) {
    max_groups_[i] = ctx.limits().maxComputeWorkGroupCount[i];
    if (local_size_[i] == 0 || local_size_[i] > ctx.limits().maxComputeWorkGroupSize[i])
      throw core::InputError(what + ": workgroup size " + std::to_string(local_size_[i]) + " in dimension " +
                             std::to_string(i) + " is outside the device limit " +
                             std::to_string(ctx.limits().maxComputeWorkGroupSize[i]));
  }
  if (std::uint64_t(local_size_[0]) * local_size_[1] * local_size_[2] > ctx.limits().maxComputeWorkGroupInvocations)
    throw core::InputError(what + ": workgroup has more invocations than the device's " +
                           std::to_string(ctx.limits().maxComputeWorkGroupInvocations));

  check_bindings(what, words, desc.sets);

  const VkDevice dev = ctx.device();
  VkShaderModuleCreateInfo mci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  mci.codeSize = words.size() * 4;
  mci.pCode = words.data();
  VkShaderModule module_handle = VK_NULL_HANDLE;
  check(vkCreateShaderModule(dev, &mci, nullptr, &module_handle), "vkCreateShaderModule");
  const DeviceHandle<VkShaderModule, vkDestroyShaderModule> module(dev, module_handle);

  std::vector<VkDescriptorSetLayout> set_handles;
  for (const auto& bindings : desc.sets) {
    set_layouts_.emplace_back(ctx, bindings);
    set_handles.push_back(set_layouts_.back().handle());
  }
  const VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, desc.push_constant_bytes};
  VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  lci.setLayoutCount = static_cast<std::uint32_t>(set_handles.size());
  lci.pSetLayouts = set_handles.data();
  lci.pushConstantRangeCount = desc.push_constant_bytes > 0 ? 1 : 0;
  lci.pPushConstantRanges = &range;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  check(vkCreatePipelineLayout(dev, &lci, nullptr, &layout), "vkCreatePipelineLayout");
  layout_ = {dev, layout};

  std::vector<VkSpecializationMapEntry> entries;
  for (std::size_t i = 0; i < desc.specialization.size(); ++i)
    entries.push_back({desc.specialization[i].id, static_cast<std::uint32_t>(i * sizeof(std::uint32_t)), 4});
  std::vector<std::uint32_t> data;
  for (const SpecConstant& c : desc.specialization) data.push_back(c.bits);
  VkSpecializationInfo spec{static_cast<std::uint32_t>(entries.size()), entries.data(), data.size() * 4, data.data()};

  VkComputePipelineCreateInfo pci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  pci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  pci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pci.stage.module = module.get();
  pci.stage.pName = "main";
  pci.stage.pSpecializationInfo = entries.empty() ? nullptr : &spec;
  pci.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  check(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &pci, nullptr, &pipeline), "vkCreateComputePipelines");
  pipeline_ = {dev, pipeline};
  ctx.set_name(VK_OBJECT_TYPE_PIPELINE, reinterpret_cast<std::uint64_t>(pipeline), desc.shader);
}

void ComputePipeline::bind(VkCommandBuffer cmd, std::initializer_list<const DescriptorSet*> sets) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_.get());
  if (sets.size() == 0) return;
  std::vector<VkDescriptorSet> handles;
  for (const DescriptorSet* s : sets) handles.push_back(s->handle());
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_.get(), 0,
                          static_cast<std::uint32_t>(handles.size()), handles.data(), 0, nullptr);
}

void ComputePipeline::push_bytes(VkCommandBuffer cmd, std::span<const std::byte> bytes) const {
  if (bytes.size() != push_bytes_)
    throw core::InputError("gpu::ComputePipeline '" + shader_ + "': " + std::to_string(bytes.size()) +
                           " push-constant bytes given, the layout has " + std::to_string(push_bytes_));
  vkCmdPushConstants(cmd, layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes_, bytes.data());
}

void ComputePipeline::dispatch(VkCommandBuffer cmd, std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
  const std::uint32_t threads[3] = {x, y, z};
  std::uint32_t groups[3];
  for (int i = 0; i < 3; ++i) {
    groups[i] = static_cast<std::uint32_t>((std::uint64_t(threads[i]) + local_size_[i] - 1) / local_size_[i]);
    if (groups[i] > max_groups_[i])
      throw core::InputError("gpu::ComputePipeline '" + shader_ + "': " + std::to_string(groups[i]) +
                             " workgroups in dimension " + std::to_string(i) + " exceed the device limit " +
                             std::to_string(max_groups_[i]));
  }
  vkCmdDispatch(cmd, groups[0], groups[1], groups[2]);
}

void ComputePipeline::dispatch_indirect(VkCommandBuffer cmd, const Buffer& args, VkDeviceSize offset) const {
  if (offset % 4 != 0 || offset + sizeof(VkDispatchIndirectCommand) > args.size())
    throw std::out_of_range("gpu::ComputePipeline '" + shader_ + "': indirect arguments at byte " +
                            std::to_string(offset) + " of a buffer of " + std::to_string(args.size()));
  vkCmdDispatchIndirect(cmd, args.handle(), offset);
}

void ComputePipeline::dispatch_linear(VkCommandBuffer cmd, std::uint32_t count) const {
  const std::uint64_t groups = (std::uint64_t(count) + local_size_[0] - 1) / local_size_[0];
  // Rows of at most max_x groups, as even as the rounding allows.
  const std::uint64_t rows = std::max<std::uint64_t>(1, (groups + max_groups_[0] - 1) / max_groups_[0]);
  const std::uint64_t per_row = (groups + rows - 1) / rows;
  if (rows > max_groups_[1])
    throw core::InputError("gpu::ComputePipeline '" + shader_ + "': " + std::to_string(count) +
                           " invocations need " + std::to_string(rows) + " rows of workgroups, more than the device's " +
                           std::to_string(max_groups_[1]));
  vkCmdDispatch(cmd, std::uint32_t(per_row), std::uint32_t(rows), 1);
}

}  // namespace fovea::gpu
