#include "text.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace fovea::devices::detail {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

void split_fields(std::string_view line, char sep, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t start = 0;
  bool quoted = false;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i < line.size() && line[i] == '"') quoted = !quoted;
    if (i == line.size() || (line[i] == sep && !quoted)) {
      std::string_view f = trim(line.substr(start, i - start));
      if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
      out.push_back(f);
      start = i + 1;
    }
  }
}

void split_blank(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
}

Num parse_double(std::string_view s, double& v) {
  s = trim(s);
  if (s.empty()) return Num::Empty;
  if (s.front() == '+') s.remove_prefix(1);
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec == std::errc::result_out_of_range) return Num::NonFinite;
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return Num::Bad;
  return std::isfinite(v) ? Num::Ok : Num::NonFinite;
}

Num parse_int64(std::string_view s, std::int64_t& v) {
  s = trim(s);
  if (s.empty()) return Num::Empty;
  if (s.front() == '+') s.remove_prefix(1);
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec == std::errc::result_out_of_range) return Num::Bad;
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) {
    double d = 0;  // "nan"/"inf" in an integer column: report them as such
    return parse_double(s, d) == Num::NonFinite ? Num::NonFinite : Num::Bad;
  }
  return Num::Ok;
}

const char* num_reason(Num n) {
  switch (n) {
    case Num::Empty: return "empty_field";
    case Num::NonFinite: return "non_finite";
    default: return "bad_number";
  }
}

}  // namespace fovea::devices::detail
