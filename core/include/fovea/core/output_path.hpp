#pragma once
// Output paths named by the user (--out DIR, OUT.png, ...): checked and prepared before any
// work is paid for, so a path that cannot be written is an InputError naming the option and
// the path (exit 2), never a failure after minutes of rendering. Missing parent directories
// are created, as `fovea render --out` always did.
#include <string>
#include <string_view>

namespace fovea::core {

// `path` is, or becomes, a writable directory. Refused: an existing non-directory, a
// directory that cannot be created or written.
void prepare_output_dir(const std::string& path, std::string_view option);

// `path` can be written as a file: not a directory, its parent directory prepared as above.
void prepare_output_file(const std::string& path, std::string_view option);

}  // namespace fovea::core
