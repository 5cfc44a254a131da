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

// The creation commands of one device: the loader's for Fovea's own, the device's own table
// for one it was handed.
struct PipelineFunctions {
  PFN_vkCreateShaderModule create_module = nullptr;
  PFN_vkDestroyShaderModule destroy_module = nullptr;
  PFN_vkCreateComputePipelines create_pipelines = nullptr;
  PFN_vkDestroyPipeline destroy_pipeline = nullptr;
};

// One compute pipeline per specialisation from one shader module, made and destroyed here.
// On a failure the pipelines made so far are destroyed and VulkanError is thrown.
std::vector<VkPipeline> build_pipelines(const PipelineFunctions& f, VkDevice dev, std::span<const std::uint32_t> words,
                                        VkPipelineLayout layout, std::span<const VkSpecializationInfo* const> specs) {
  VkShaderModuleCreateInfo mci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  mci.codeSize = words.size() * 4;
  mci.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  check(f.create_module(dev, &mci, nullptr, &module), "vkCreateShaderModule");
  std::vector<VkPipeline> out;
  VkResult r = VK_SUCCESS;
  for (const VkSpecializationInfo* spec : specs) {
    VkComputePipelineCreateInfo pci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    pci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    pci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pci.stage.module = module;
    pci.stage.pName = "main";
    pci.stage.pSpecializationInfo = spec;
    pci.layout = layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    r = f.create_pipelines(dev, VK_NULL_HANDLE, 1, &pci, nullptr, &pipeline);
    if (r != VK_SUCCESS) break;
    out.push_back(pipeline);
  }
  f.destroy_module(dev, module, nullptr);
  if (r != VK_SUCCESS) {
    for (VkPipeline p : out) f.destroy_pipeline(dev, p, nullptr);
    check(r, "vkCreateComputePipelines");
  }
  return out;
}

// A pipeline layout with the sets in order and one compute push-constant range (none for 0).
VkPipelineLayout build_layout(PFN_vkCreatePipelineLayout create, VkDevice dev,
                              std::span<const VkDescriptorSetLayout> sets, std::uint32_t push_constant_bytes) {
  const VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_constant_bytes};
  VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  lci.setLayoutCount = static_cast<std::uint32_t>(sets.size());
  lci.pSetLayouts = sets.data();
  lci.pushConstantRangeCount = push_constant_bytes > 0 ? 1 : 0;
  lci.pPushConstantRanges = &range;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  check(create(dev, &lci, nullptr, &layout), "vkCreatePipelineLayout");
  return layout;
}

// The SPIR-V's type for a descriptor type of a layout.
Binding binding_of(VkDescriptorType t) {
  switch (t) {
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER:
    case VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC: return Binding::StorageBuffer;
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER:
    case VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC: return Binding::UniformBuffer;
    case VK_DESCRIPTOR_TYPE_STORAGE_IMAGE: return Binding::StorageImage;
    case VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER: return Binding::SampledImage;
    case VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER: return Binding::TexelBuffer;
    case VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR: return Binding::AccelerationStructure;
    default: throw core::InputError("descriptor type " + std::to_string(int(t)) + " is not one the pipelines bind");
  }
}

template <class F>
F device_function(VkDevice dev, PFN_vkGetDeviceProcAddr get, const char* name) {
  const auto f = reinterpret_cast<F>(get(dev, name));
  if (!f) throw VulkanError(VK_ERROR_INITIALIZATION_FAILED, std::string("the device has no ") + name);
  return f;
}

PipelineFunctions pipeline_functions(VkDevice dev, PFN_vkGetDeviceProcAddr get) {
  return {device_function<PFN_vkCreateShaderModule>(dev, get, "vkCreateShaderModule"),
          device_function<PFN_vkDestroyShaderModule>(dev, get, "vkDestroyShaderModule"),
          device_function<PFN_vkCreateComputePipelines>(dev, get, "vkCreateComputePipelines"),
          device_function<PFN_vkDestroyPipeline>(dev, get, "vkDestroyPipeline")};
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

namespace {

// A description as the kernel cache's key: every field that changes the compiled kernel.
std::string kernel_key(const ComputePipelineDesc& desc) {
  std::string key = desc.shader + "|push " + std::to_string(desc.push_constant_bytes);
  for (const auto& set : desc.sets) {
    key += "|set";
    for (const Binding b : set) key += ' ' + std::to_string(int(b));
  }
  for (const SpecConstant& c : desc.specialization) key += "|" + std::to_string(c.id) + '=' + std::to_string(c.bits);
  return key;
}

std::shared_ptr<const CompiledKernel> compile_kernel(Context& ctx, const ComputePipelineDesc& desc) {
  const std::string what = "gpu::ComputePipeline '" + desc.shader + "'";
  const std::vector<std::uint32_t> words = spirv_words(desc.shader, what);
  if (desc.push_constant_bytes % 4 != 0 || desc.push_constant_bytes > ctx.limits().maxPushConstantsSize)
    throw core::InputError(what + ": push_constant_bytes " + std::to_string(desc.push_constant_bytes) +
                           " must be a multiple of 4 and at most " + std::to_string(ctx.limits().maxPushConstantsSize));
  auto kernel = std::make_shared<CompiledKernel>();
  kernel->local_size = spirv::workgroup_size(words, desc.specialization);
  for (int i = 0; i < 3; ++i)
    if (kernel->local_size[i] == 0 || kernel->local_size[i] > ctx.limits().maxComputeWorkGroupSize[i])
      throw core::InputError(what + ": workgroup size " + std::to_string(kernel->local_size[i]) + " in dimension " +
                             std::to_string(i) + " is outside the device limit " +
                             std::to_string(ctx.limits().maxComputeWorkGroupSize[i]));
  if (std::uint64_t(kernel->local_size[0]) * kernel->local_size[1] * kernel->local_size[2] >
      ctx.limits().maxComputeWorkGroupInvocations)
    throw core::InputError(what + ": workgroup has more invocations than the device's " +
                           std::to_string(ctx.limits().maxComputeWorkGroupInvocations));

  check_bindings(what, words, desc.sets);

  const VkDevice dev = ctx.device();
  std::vector<VkDescriptorSetLayout> set_handles;
  for (const auto& bindings : desc.sets) {
    kernel->set_layouts.emplace_back(ctx, bindings);
    set_handles.push_back(kernel->set_layouts.back().handle());
  }
  const VkPipelineLayout layout = build_layout(&vkCreatePipelineLayout, dev, set_handles, desc.push_constant_bytes);
  kernel->layout = {dev, layout};

  std::vector<VkSpecializationMapEntry> entries;
  for (std::size_t i = 0; i < desc.specialization.size(); ++i)
    entries.push_back({desc.specialization[i].id, static_cast<std::uint32_t>(i * sizeof(std::uint32_t)), 4});
  std::vector<std::uint32_t> data;
  for (const SpecConstant& c : desc.specialization) data.push_back(c.bits);
  VkSpecializationInfo spec{static_cast<std::uint32_t>(entries.size()), entries.data(), data.size() * 4, data.data()};

  const VkSpecializationInfo* specs[1] = {entries.empty() ? nullptr : &spec};
  const PipelineFunctions loader{&vkCreateShaderModule, &vkDestroyShaderModule, &vkCreateComputePipelines,
                                 &vkDestroyPipeline};
  const VkPipeline pipeline = build_pipelines(loader, dev, words, layout, specs).front();
  kernel->pipeline = {dev, pipeline};
  ctx.set_name(VK_OBJECT_TYPE_PIPELINE, reinterpret_cast<std::uint64_t>(pipeline), desc.shader);
  return kernel;
}

}  // namespace

ComputePipeline::ComputePipeline(Context& ctx, const ComputePipelineDesc& desc)
    : shader_(desc.shader),
      push_bytes_(desc.push_constant_bytes),
      kernel_(ctx.kernel(kernel_key(desc), [&] { return compile_kernel(ctx, desc); })) {
  for (int i = 0; i < 3; ++i) max_groups_[i] = ctx.limits().maxComputeWorkGroupCount[i];
}

const DescriptorSetLayout& ComputePipeline::set_layout(std::size_t set) const {
  if (!kernel_) throw std::out_of_range("gpu::ComputePipeline: an empty pipeline has no set " + std::to_string(set));
  return kernel_->set_layouts.at(set);
}

void ComputePipeline::bind(VkCommandBuffer cmd, std::initializer_list<const DescriptorSet*> sets) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, handle());
  if (sets.size() == 0) return;
  std::vector<VkDescriptorSet> handles;
  for (const DescriptorSet* s : sets) handles.push_back(s->handle());
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout(), 0,
                          static_cast<std::uint32_t>(handles.size()), handles.data(), 0, nullptr);
}

void ComputePipeline::push_bytes(VkCommandBuffer cmd, std::span<const std::byte> bytes) const {
  if (bytes.size() != push_bytes_)
    throw core::InputError("gpu::ComputePipeline '" + shader_ + "': " + std::to_string(bytes.size()) +
                           " push-constant bytes given, the layout has " + std::to_string(push_bytes_));
  vkCmdPushConstants(cmd, layout(), VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes_, bytes.data());
}

void ComputePipeline::dispatch(VkCommandBuffer cmd, std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
  const std::uint32_t threads[3] = {x, y, z};
  const std::array<std::uint32_t, 3> size = workgroup_size();
  std::uint32_t groups[3];
  for (int i = 0; i < 3; ++i) {
    groups[i] = static_cast<std::uint32_t>((std::uint64_t(threads[i]) + size[i] - 1) / size[i]);
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
  const std::uint64_t size = workgroup_size()[0];
  const std::uint64_t groups = (std::uint64_t(count) + size - 1) / size;
  // Rows of at most max_x groups, as even as the rounding allows.
  const std::uint64_t rows = std::max<std::uint64_t>(1, (groups + max_groups_[0] - 1) / max_groups_[0]);
  const std::uint64_t per_row = (groups + rows - 1) / rows;
  if (rows > max_groups_[1])
    throw core::InputError("gpu::ComputePipeline '" + shader_ + "': " + std::to_string(count) +
                           " invocations need " + std::to_string(rows) + " rows of workgroups, more than the device's " +
                           std::to_string(max_groups_[1]));
  vkCmdDispatch(cmd, std::uint32_t(per_row), std::uint32_t(rows), 1);
}

ForeignPipelines create_foreign_pipelines(VkDevice dev, PFN_vkGetDeviceProcAddr get, const ForeignPipelineDesc& desc) {
  const std::string what = "gpu::create_foreign_pipelines '" + desc.shader + "'";
  const std::vector<std::uint32_t> words = spirv_words(desc.shader, what);
  std::vector<Binding> types;
  for (VkDescriptorType t : desc.bindings) types.push_back(binding_of(t));
  check_bindings(what, words, {types});
  if (desc.push_constant_bytes % 4 != 0)
    throw core::InputError(what + ": push_constant_bytes " + std::to_string(desc.push_constant_bytes) +
                           " is not a multiple of 4");
  const PipelineFunctions f = pipeline_functions(dev, get);
  const auto create_set_layout =
      device_function<PFN_vkCreateDescriptorSetLayout>(dev, get, "vkCreateDescriptorSetLayout");
  const auto create_layout = device_function<PFN_vkCreatePipelineLayout>(dev, get, "vkCreatePipelineLayout");

  ForeignPipelines out;
  try {
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    for (std::uint32_t b = 0; b < desc.bindings.size(); ++b)
      bindings.push_back({b, desc.bindings[b], 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    li.bindingCount = std::uint32_t(bindings.size());
    li.pBindings = bindings.data();
    check(create_set_layout(dev, &li, nullptr, &out.set_layout), "vkCreateDescriptorSetLayout");
    out.layout = build_layout(create_layout, dev, {&out.set_layout, 1}, desc.push_constant_bytes);

    std::vector<std::vector<VkSpecializationMapEntry>> entries;  // each info points into one
    std::vector<VkSpecializationInfo> infos;
    entries.reserve(desc.specializations.size());
    for (const std::vector<std::uint32_t>& values : desc.specializations) {
      auto& e = entries.emplace_back();
      for (std::uint32_t id = 0; id < values.size(); ++id) e.push_back({id, id * 4, 4});
      infos.push_back({std::uint32_t(e.size()), e.data(), values.size() * 4, values.data()});
    }
    std::vector<const VkSpecializationInfo*> specs;
    for (const VkSpecializationInfo& i : infos) specs.push_back(&i);
    if (specs.empty()) specs.push_back(nullptr);
    out.pipelines = build_pipelines(f, dev, words, out.layout, specs);
  } catch (...) {
    destroy_foreign_pipelines(dev, get, out);
    throw;
  }
  return out;
}

void destroy_foreign_pipelines(VkDevice dev, PFN_vkGetDeviceProcAddr get, ForeignPipelines& p) {
  for (VkPipeline pipeline : p.pipelines)
    device_function<PFN_vkDestroyPipeline>(dev, get, "vkDestroyPipeline")(dev, pipeline, nullptr);
  if (p.layout)
    device_function<PFN_vkDestroyPipelineLayout>(dev, get, "vkDestroyPipelineLayout")(dev, p.layout, nullptr);
  if (p.set_layout)
    device_function<PFN_vkDestroyDescriptorSetLayout>(dev, get, "vkDestroyDescriptorSetLayout")(dev, p.set_layout,
                                                                                                  nullptr);
  p = {};
}

}  // namespace fovea::gpu
