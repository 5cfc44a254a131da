#include "fovea/xrcommon/log.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace fovea::xrcommon {

const char* log_level_name(LogLevel level) {
  switch (level) {
    case LogLevel::Error: return "error";
    case LogLevel::Warn: return "warn";
    case LogLevel::Info: return "info";
    case LogLevel::Debug: return "debug";
  }
  return "?";
}

LogLevel log_level_from_env(const char* var, LogLevel fallback) {
  const char* s = std::getenv(var);
  if (!s) return fallback;
  for (LogLevel l : {LogLevel::Error, LogLevel::Warn, LogLevel::Info, LogLevel::Debug})
    if (!std::strcmp(s, log_level_name(l))) return l;
  return fallback;
}

Logger::Logger(std::string tag, LogLevel stderr_level, LogLevel file_level)
    : tag_(std::move(tag)), stderr_level_(stderr_level), file_level_(file_level) {}

Logger::~Logger() {
  if (file_) std::fclose(file_);
}

bool Logger::open(const std::string& path, const char* what, LogLevel failure) {
  std::lock_guard lock(mutex_);
  if (file_) std::fclose(file_);
  file_ = nullptr;
  if (path.empty()) return false;
  file_ = std::fopen(path.c_str(), "a");
  if (!file_)
    std::fprintf(stderr, "%s %s: cannot open %s \"%s\": %s; logging to stderr only\n", tag_.c_str(),
                 log_level_name(failure), what, path.c_str(), std::strerror(errno));
  return file_ != nullptr;
}

void Logger::write(LogLevel level, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vwrite(level, fmt, ap);
  va_end(ap);
}

void Logger::vwrite(LogLevel level, const char* fmt, va_list ap) {
  const bool to_stderr = level <= stderr_level_;
  std::lock_guard lock(mutex_);
  const bool to_file = file_ && level <= file_level_;
  if (!to_stderr && !to_file) return;
  char buf[2048];
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  if (to_stderr) std::fprintf(stderr, "%s %s: %s\n", tag_.c_str(), log_level_name(level), buf);
  if (to_file) {
    std::fprintf(file_, "%s: %s\n", log_level_name(level), buf);
    std::fflush(file_);
  }
}

}  // namespace fovea::xrcommon
