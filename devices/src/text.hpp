#pragma once
// Small text helpers for the readers: field splitting and strict number parsing.
#include <cstdint>
#include <string_view>
#include <vector>

namespace fovea::devices::detail {

// Splits on `sep`; fields are trimmed of blanks and of one pair of surrounding quotes.
void split_fields(std::string_view line, char sep, std::vector<std::string_view>& out);
// Splits on runs of blanks (spaces/tabs).
void split_blank(std::string_view line, std::vector<std::string_view>& out);
std::string_view trim(std::string_view s);

enum class Num { Ok, Empty, Bad, NonFinite };
Num parse_double(std::string_view s, double& v);
Num parse_int64(std::string_view s, std::int64_t& v);

// Drop reason for a failed parse ("empty_field", "bad_number", "non_finite").
const char* num_reason(Num n);

}  // namespace fovea::devices::detail
