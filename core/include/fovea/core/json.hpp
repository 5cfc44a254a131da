#pragma once
// JSON text parsed in one translation unit (core/src/json.cpp). nlohmann::json::parse
// instantiates the library's lexer and parser in every file that calls it: 8.6 s (a stream)
// to 13.7 s (a string) of compile time per file with the sanitizers, 3 s in Release
// (docs/building.md, "Build and test time").
// Same results and exceptions as nlohmann::json::parse.
#include <istream>
#include <string_view>

#include <nlohmann/json.hpp>

namespace fovea::core {

nlohmann::json parse_json(std::string_view text);
nlohmann::json parse_json(std::istream& in);
// nlohmann::json::parse(in, nullptr, false): a discarded value (is_discarded()) instead of
// an exception on malformed text.
nlohmann::json parse_json_or_discarded(std::istream& in);

}  // namespace fovea::core
