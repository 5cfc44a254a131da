#pragma once
// Runs the `fovea` binary built alongside the tests.
#include <string>

namespace fovea::test {

struct CliResult {
  int status = -1;  // exit code
  std::string out, err;
};

// `args` is appended to the executable path as-is (shell words).
CliResult run_fovea(const std::string& args);

// The whole file as text ("" when it cannot be read).
std::string read_text(const std::string& path);

// A fresh empty directory under the system temp dir, removed by the caller if wanted.
std::string temp_dir(const std::string& tag);

}  // namespace fovea::test
