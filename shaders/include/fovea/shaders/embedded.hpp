#pragma once
// SPIR-V of every shader in shaders/, embedded at build time.
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace fovea::shaders {
// Bytes of "<file>.comp.spv", or an empty span when no such shader was built.
std::span<const std::uint8_t> find(std::string_view name);
std::vector<std::string_view> names();
}  // namespace fovea::shaders
