#pragma once
// Bounds applied to outside input before a parser sees it: whole-file reads that refuse
// endless or oversized files, and the nesting depth of JSON text (recursive parsers
// overflow the stack on deeply nested arrays/objects).
#include <cstddef>
#include <string>
#include <string_view>

namespace fovea::core {

// Reads a regular file whole. Throws InputError naming `path` if it is not a regular
// file, unreadable, or longer than `max_bytes` (devices such as /dev/zero never end).
std::string read_file_bounded(const std::string& path, std::size_t max_bytes);

// Deepest nesting of arrays and objects in JSON text, string contents skipped. Counting
// stops at `stop_at` (the result is then stop_at), so the scan is linear and bounded.
std::size_t json_nesting_depth(std::string_view text, std::size_t stop_at);

// Throws InputError ("ORIGIN: JSON nested deeper than N levels") when the text nests
// deeper than `max_depth`.
void check_json_nesting(std::string_view text, std::string_view origin, std::size_t max_depth);

}  // namespace fovea::core
