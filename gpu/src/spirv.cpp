#include "spirv.hpp"

#include <optional>
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

}  // namespace

std::array<std::uint32_t, 3> workgroup_size(std::span<const std::uint32_t> words,
                                            std::span<const SpecConstant> specialization) {
  if (words.size() < 5 || words[0] != kMagic) throw core::InputError("SPIR-V: bad header");
  std::optional<std::array<std::uint32_t, 3>> literal;  // LocalSize
  std::optional<std::array<std::uint32_t, 3>> ids;      // LocalSizeId operands
  std::optional<std::uint32_t> builtin_id;              // id decorated WorkgroupSize
  std::unordered_map<std::uint32_t, std::uint32_t> spec_id;     // result id -> SpecId
  std::unordered_map<std::uint32_t, std::uint32_t> scalar;      // result id -> default value
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> composite;  // result id -> members

  for (std::size_t i = 5; i < words.size();) {
    const std::uint32_t count = words[i] >> 16, op = words[i] & 0xffff;
    if (count == 0 || i + count > words.size()) throw core::InputError("SPIR-V: truncated instruction");
    const std::uint32_t* w = &words[i];
    if ((op == kOpExecutionMode && count >= 6 && w[2] == kModeLocalSize) ||
        (op == kOpExecutionModeId && count >= 6 && w[2] == kModeLocalSizeId)) {
      (w[2] == kModeLocalSize ? literal : ids) = std::array<std::uint32_t, 3>{w[3], w[4], w[5]};
    } else if (op == kOpDecorate && count >= 4) {
      if (w[2] == kDecorationSpecId) spec_id[w[1]] = w[3];
      if (w[2] == kDecorationBuiltIn && w[3] == kBuiltInWorkgroupSize) builtin_id = w[1];
    } else if ((op == kOpConstant || op == kOpSpecConstant) && count >= 4) {
      scalar[w[2]] = w[3];  // 32-bit integer constants: one literal word
    } else if ((op == kOpConstantComposite || op == kOpSpecConstantComposite) && count >= 3) {
      composite[w[2]].assign(w + 3, w + count);
    }
    i += count;
  }

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

}  // namespace fovea::gpu::spirv
