#pragma once
// Runs an OpenXR application (hello_xr) headless against the Fovea runtime for tests:
// environment overrides, stdin held open (hello_xr quits when stdin reaches EOF), output
// captured, a hard timeout.
#include <map>
#include <string>
#include <vector>

namespace fovea::test {

struct ProcessResult {
  int exit_code = -1;  // -1 when killed or not started
  bool timed_out = false;
  std::string output;  // stdout and stderr, interleaved
};

ProcessResult run_process(const std::vector<std::string>& argv, const std::map<std::string, std::string>& env,
                          int timeout_s);

// A fresh temporary directory (removed by the destructor unless keep() was called).
class TempDir {
 public:
  explicit TempDir(const std::string& tag);
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  void keep() { keep_ = true; }

 private:
  std::string path_;
  bool keep_ = false;
};

// The environment for a headless hello_xr run on the Fovea runtime writing into `out`.
std::map<std::string, std::string> runtime_env(const std::string& out, int exit_after_frames, int png_every);

std::string read_text(const std::string& path);

}  // namespace fovea::test
