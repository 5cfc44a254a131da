#include "fovea/core/input_limits.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>

#include "fovea/core/error.hpp"

namespace fovea::core {

std::string read_file_bounded(const std::string& path, std::size_t max_bytes) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": not a readable file");
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) throw InputError(path + ": not a readable file");
  // Read in chunks rather than trusting the size reported up front: the file may grow.
  std::string out;
  char chunk[64 * 1024];
  for (;;) {
    const std::size_t n = std::fread(chunk, 1, sizeof chunk, f.get());
    if (n > max_bytes - out.size())
      throw InputError(path + ": larger than " + std::to_string(max_bytes) + " bytes, refused");
    out.append(chunk, n);
    if (n < sizeof chunk) break;
  }
  if (std::ferror(f.get())) throw InputError(path + ": read error");
  return out;
}

std::size_t json_nesting_depth(std::string_view text, std::size_t stop_at) {
  std::size_t depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (const char ch : text) {
    if (in_string) {
      if (escaped) escaped = false;
      else if (ch == '\\') escaped = true;
      else if (ch == '"') in_string = false;
      continue;
    }
    if (ch == '"') {
      in_string = true;
    } else if (ch == '[' || ch == '{') {
      if (++depth > deepest) deepest = depth;
      if (deepest >= stop_at) return stop_at;
    } else if ((ch == ']' || ch == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

void check_json_nesting(std::string_view text, std::string_view origin, std::size_t max_depth) {
  if (json_nesting_depth(text, max_depth + 1) > max_depth)
    throw InputError(std::string(origin) + ": JSON nested deeper than " + std::to_string(max_depth) +
                     " levels, refused");
}

}  // namespace fovea::core
