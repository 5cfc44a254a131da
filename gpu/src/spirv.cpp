#include "spirv.hpp"

#include <algorithm>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "fovea/core/error.hpp"

namespace fovea::gpu::spirv {
namespace {

// Opcodes, execution modes and decorations from the SPIR-V specification.
constexpr std::uint32_t kMagic = 0x07230203;
constexpr std::uint32_t kOpExecutionMode = 16, kOpExecutionModeId = 331, kOpDecorate = 71;
constexpr std::uint32_t kOpConstant = 43, kOpConstantComposite = 44, kOpSpecConstant = 50,
                        kOpSpecConstantComposite = 51;
constexpr std::uint32_t kModeLocalSize = 17, kModeLocalSizeId = 38;
constexpr std::uint32_t kDecorationSpecId = 1, kDecorationBuiltIn = 11, kBuiltInWorkgroupSize = 25;
constexpr std::uint32_t kDimBuffer = 5;  // OpTypeImage's Dim operand for textureBuffer / samplerBuffer
constexpr std::uint32_t kOpTypeImage = 25, kOpTypeSampledImage = 27, kOpTypeArray = 28, kOpTypeRuntimeArray = 29,
                        kOpTypePointer = 32, kOpVariable = 59;
constexpr std::uint32_t kOpTypeAccelerationStructureKHR = 5341;
constexpr std::uint32_t kDecorationBufferBlock = 3, kDecorationBinding = 33, kDecorationDescriptorSet = 34;
constexpr std::uint32_t kStorageUniformConstant = 0, kStorageUniform = 2, kStorageStorageBuffer = 12;

// Calls f(opcode, words of the instruction) for each instruction after the header.
template <class F>
void for_each_instruction(std::span<const std::uint32_t> words, F f) {
  if (words.size() < 5 || words[0] != kMagic) throw core::InputError("SPIR-V: bad header");
  for (std::size_t i = 5; i < words.size();) {
    const std::uint32_t count = words[i] >> 16, op = words[i] & 0xffff;
    if (count == 0 || i + count > words.size()) throw core::InputError("SPIR-V: truncated instruction");
    f(op, std::span<const std::uint32_t>(&words[i], count));
    i += count;
  }
}

}  // namespace

std::array<std::uint32_t, 3> workgroup_size(std::span<const std::uint32_t> words,
                                            std::span<const SpecConstant> specialization) {
  std::optional<std::array<std::uint32_t, 3>> literal;  // LocalSize
  std::optional<std::array<std::uint32_t, 3>> ids;      // LocalSizeId operands
  std::optional<std::uint32_t> builtin_id;              // id decorated WorkgroupSize
  std::unordered_map<std::uint32_t, std::uint32_t> spec_id;     // result id -> SpecId
  std::unordered_map<std::uint32_t, std::uint32_t> scalar;      // result id -> default value
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> composite;  // result id -> members

  for_each_instruction(words, [&](std::uint32_t op, std::span<const std::uint32_t> w) {
    const std::size_t count = w.size();
    if ((op == kOpExecutionMode && count >= 6 && w[2] == kModeLocalSize) ||
        (op == kOpExecutionModeId && count >= 6 && w[2] == kModeLocalSizeId)) {
      (w[2] == kModeLocalSize ? literal : ids) = std::array<std::uint32_t, 3>{w[3], w[4], w[5]};
    } else if (op == kOpDecorate && count >= 4) {
      if (w[2] == kDecorationSpecId) spec_id[w[1]] = w[3];
      if (w[2] == kDecorationBuiltIn && w[3] == kBuiltInWorkgroupSize) builtin_id = w[1];
    } else if ((op == kOpConstant || op == kOpSpecConstant) && count >= 4) {
      scalar[w[2]] = w[3];  // 32-bit integer constants: one literal word
    } else if ((op == kOpConstantComposite || op == kOpSpecConstantComposite) && count >= 3) {
      composite[w[2]].assign(w.begin() + 3, w.end());
    }
  });

  auto value = [&](std::uint32_t id) {
    if (auto s = spec_id.find(id); s != spec_id.end())
      for (const SpecConstant& c : specialization)
        if (c.id == s->second) return c.bits;
    auto v = scalar.find(id);
    if (v == scalar.end()) throw core::InputError("SPIR-V: workgroup size refers to an unknown constant");
    return v->second;
  };
  if (builtin_id) {
    auto c = composite.find(*builtin_id);
    if (c == composite.end() || c->second.size() != 3)
      throw core::InputError("SPIR-V: WorkgroupSize is not a 3-component constant");
    return {value(c->second[0]), value(c->second[1]), value(c->second[2])};
  }
  if (ids) return {value((*ids)[0]), value((*ids)[1]), value((*ids)[2])};
  if (literal) return *literal;
  throw core::InputError("SPIR-V: no workgroup size (not a compute shader?)");
}

std::vector<DeclaredBinding> descriptor_bindings(std::span<const std::uint32_t> words) {
  struct Pointer {
    std::uint32_t storage, pointee;
  };
  std::unordered_map<std::uint32_t, std::uint32_t> set_of, binding_of;  // variable id -> decoration
  std::unordered_map<std::uint32_t, bool> buffer_block;                 // struct id decorated BufferBlock
  std::unordered_map<std::uint32_t, Pointer> pointers;                  // pointer type id
  std::unordered_map<std::uint32_t, std::uint32_t> element;             // array type id -> element type
  std::unordered_map<std::uint32_t, std::uint32_t> image_sampled;       // image type id -> Sampled operand
  std::unordered_map<std::uint32_t, bool> buffer_image;                 // image type ids of Dim Buffer
  std::unordered_map<std::uint32_t, bool> sampled_image;                // OpTypeSampledImage id -> of a Dim Buffer image
  std::unordered_map<std::uint32_t, bool> accel;                        // OpTypeAccelerationStructureKHR ids
  std::vector<std::pair<std::uint32_t, std::uint32_t>> variables;       // (id, pointer type)
  for_each_instruction(words, [&](std::uint32_t op, std::span<const std::uint32_t> w) {
    const std::size_t count = w.size();
    if (op == kOpDecorate && count >= 3) {
      if (w[2] == kDecorationDescriptorSet && count >= 4) set_of[w[1]] = w[3];
      if (w[2] == kDecorationBinding && count >= 4) binding_of[w[1]] = w[3];
      if (w[2] == kDecorationBufferBlock) buffer_block[w[1]] = true;
    } else if (op == kOpTypePointer && count >= 4) {
      pointers[w[1]] = {w[2], w[3]};
    } else if ((op == kOpTypeArray || op == kOpTypeRuntimeArray) && count >= 3) {
      element[w[1]] = w[2];
    } else if (op == kOpTypeImage && count >= 8) {
      image_sampled[w[1]] = w[7];
      if (w[3] == kDimBuffer) buffer_image[w[1]] = true;
    } else if (op == kOpTypeSampledImage && count >= 3) {
      sampled_image[w[1]] = buffer_image.count(w[2]) != 0;
    } else if (op == kOpTypeAccelerationStructureKHR && count >= 2) {
      accel[w[1]] = true;
    } else if (op == kOpVariable && count >= 4) {
      variables.emplace_back(w[2], w[1]);
    }
  });

  std::vector<DeclaredBinding> out;
  for (const auto& [id, type] : variables) {
    const auto b = binding_of.find(id);
    if (b == binding_of.end()) continue;  // not a descriptor (push constants, built-ins)
    const auto p = pointers.find(type);
    if (p == pointers.end()) throw core::InputError("SPIR-V: variable " + std::to_string(id) + " has no pointer type");
    std::uint32_t t = p->second.pointee;
    while (element.count(t)) t = element[t];  // arrays of resources: the element decides
    DeclaredBinding d;
    d.set = set_of.count(id) ? set_of[id] : 0;
    d.binding = b->second;
    const std::uint32_t storage = p->second.storage;
    if (storage == kStorageStorageBuffer || (storage == kStorageUniform && buffer_block.count(t))) {
      d.type = Binding::StorageBuffer;
    } else if (storage == kStorageUniform) {
      d.type = Binding::UniformBuffer;
    } else if (storage == kStorageUniformConstant && sampled_image.count(t)) {
      d.type = sampled_image[t] ? Binding::TexelBuffer : Binding::SampledImage;  // samplerBuffer / sampler2D
    } else if (storage == kStorageUniformConstant && buffer_image.count(t) && image_sampled[t] == 1) {
      d.type = Binding::TexelBuffer;  // textureBuffer (GL_EXT_samplerless_texture_functions)
    } else if (storage == kStorageUniformConstant && accel.count(t)) {
      d.type = Binding::AccelerationStructure;
    } else if (storage == kStorageUniformConstant && image_sampled.count(t) && image_sampled[t] == 2) {
      d.type = Binding::StorageImage;
    } else {
      throw core::InputError("SPIR-V: set " + std::to_string(d.set) + " binding " + std::to_string(d.binding) +
                             " has a resource type the pipelines do not bind");
    }
    out.push_back(d);
  }
  std::sort(out.begin(), out.end(), [](const DeclaredBinding& a, const DeclaredBinding& b) {
    return a.set != b.set ? a.set < b.set : a.binding < b.binding;
  });
  return out;
}

}  // namespace fovea::gpu::spirv
