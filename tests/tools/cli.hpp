#pragma once
// Runs the `fovea` binary built alongside the tests.
#include <cstdlib>
#include <optional>
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

// FOVEA_PYTHON set for the scope: the interpreter the commands run.
struct PythonOverride {
  explicit PythonOverride(const char* p) { setenv("FOVEA_PYTHON", p, 1); }
  ~PythonOverride() { unsetenv("FOVEA_PYTHON"); }
  PythonOverride(const PythonOverride&) = delete;
  PythonOverride& operator=(const PythonOverride&) = delete;
};

// Whether the commands draw their figures: matplotlib does in the Release build. Under the
// sanitizers, which do not see Python, they run without it (FiguresAsData for the scope) and
// the tests read the figures' data, which the sanitized program writes: drawing was most of
// those tests' time there.
#ifdef FOVEA_SANITIZED_BUILD
inline constexpr bool kFiguresDrawn = false;
#else
inline constexpr bool kFiguresDrawn = true;
#endif
struct FiguresAsData {
  FiguresAsData() {
    if (!kFiguresDrawn) python.emplace("/nonexistent/python3");
  }
  std::optional<PythonOverride> python;
};

}  // namespace fovea::test
