#include "log.hpp"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace fovea::runtime::log {
namespace {

std::mutex g_mutex;
FILE* g_file = nullptr;

Level stderr_level() {
  static const Level level = [] {
    const char* s = std::getenv("FOVEA_RUNTIME_LOG");
    if (!s) return Level::Warn;
    if (!std::strcmp(s, "error")) return Level::Error;
    if (!std::strcmp(s, "info")) return Level::Info;
    if (!std::strcmp(s, "debug")) return Level::Debug;
    return Level::Warn;
  }();
  return level;
}

const char* name(Level l) {
  switch (l) {
    case Level::Error: return "error";
    case Level::Warn: return "warn";
    case Level::Info: return "info";
    case Level::Debug: return "debug";
  }
  return "?";
}

}  // namespace

void set_file_dir(const std::string& dir) {
  std::lock_guard lock(g_mutex);
  if (g_file) std::fclose(g_file);
  g_file = nullptr;
  if (dir.empty()) return;
  const std::string path = dir + "/runtime.log";
  g_file = std::fopen(path.c_str(), "a");
  if (!g_file) std::fprintf(stderr, "[fovea-runtime] error: %s: cannot open: %s\n", path.c_str(), std::strerror(errno));
}

void write(Level level, const char* fmt, ...) {
  const bool to_stderr = level <= stderr_level();
  std::lock_guard lock(g_mutex);
  const bool to_file = g_file && level <= Level::Info;
  if (!to_stderr && !to_file) return;
  char buf[2048];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  if (to_stderr) std::fprintf(stderr, "[fovea-runtime] %s: %s\n", name(level), buf);
  if (to_file) {
    std::fprintf(g_file, "%s: %s\n", name(level), buf);
    std::fflush(g_file);
  }
}

}  // namespace fovea::runtime::log
