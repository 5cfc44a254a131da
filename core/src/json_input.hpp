#pragma once
// JSON from outside (display presets, lens parameters): parsed with its nesting bounded;
// every library error (syntax, a number beyond the range of double) becomes InputError
// naming the input and the key whose value was being read.
#include <string_view>

#include <nlohmann/json.hpp>

namespace fovea::core::detail {

constexpr std::size_t kMaxJsonDepth = 64;

nlohmann::json parse_json_input(std::string_view text, std::string_view origin);

// The library's message without its "[json.exception.type.N] " prefix.
std::string json_error_text(const nlohmann::json::exception& e);

}  // namespace fovea::core::detail
