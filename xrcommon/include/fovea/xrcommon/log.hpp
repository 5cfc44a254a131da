#pragma once
// The leveled logger of the OpenXR runtime and the API layer: each configures its own
// thresholds, stderr tag and file (the runtime's FOVEA_RUNTIME_LOG and runtime.log, the
// layer's FOVEA_LAYER_LOG_LEVEL and FOVEA_LAYER_LOG_FILE). Lines are "<tag> <level>: text" on
// stderr and "<level>: text" in the file, each written whole under one lock.
#include <cstdarg>
#include <cstdio>
#include <mutex>
#include <string>

namespace fovea::xrcommon {

enum class LogLevel { Error = 0, Warn = 1, Info = 2, Debug = 3 };

const char* log_level_name(LogLevel level);
// The level environment variable `var` names (error|warn|info|debug); unset or any other
// value: `fallback`.
LogLevel log_level_from_env(const char* var, LogLevel fallback);

class Logger {
 public:
  // Messages at or below `stderr_level` go to stderr, at or below `file_level` to the file.
  Logger(std::string tag, LogLevel stderr_level, LogLevel file_level);
  ~Logger();
  Logger(const Logger&) = delete;
  Logger& operator=(const Logger&) = delete;

  // Appends to `path` from now on (empty: no file). A file that cannot be opened is reported
  // on stderr at `failure` level, naming `what` (the variable it came from), the path and the
  // reason; messages then reach stderr only. Returns whether a file is open.
  bool open(const std::string& path, const char* what, LogLevel failure);
  void write(LogLevel level, const char* fmt, ...) __attribute__((format(printf, 3, 4)));
  void vwrite(LogLevel level, const char* fmt, va_list ap);

 private:
  const std::string tag_;
  const LogLevel stderr_level_, file_level_;
  std::mutex mutex_;
  std::FILE* file_ = nullptr;
};

}  // namespace fovea::xrcommon
