#include "log.hpp"

#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace fovea::layer::log {
namespace {

Level configured_level() {
  const char* s = std::getenv("FOVEA_LAYER_LOG_LEVEL");
  if (!s) return Level::Info;
  if (!std::strcmp(s, "error")) return Level::Error;
  if (!std::strcmp(s, "warn")) return Level::Warn;
  if (!std::strcmp(s, "debug")) return Level::Debug;
  return Level::Info;
}

const char* name(Level l) {
  constexpr const char* names[] = {"error", "warn", "info", "debug"};
  return names[int(l)];
}

}  // namespace

void write(Level level, const char* fmt, ...) {
  static std::mutex mutex;
  static const Level max_level = configured_level();
  static FILE* file = [] {
    const char* path = std::getenv("FOVEA_LAYER_LOG_FILE");
    if (!path || !*path) return static_cast<FILE*>(nullptr);
    FILE* f = std::fopen(path, "a");
    // The layer keeps working; the messages still reach stderr from warn up.
    if (!f)
      std::fprintf(stderr, "[fovea-layer] warn: cannot open FOVEA_LAYER_LOG_FILE \"%s\": %s; logging to stderr only\n",
                   path, std::strerror(errno));
    return f;
  }();
  if (level > max_level) return;
  char buf[2048];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  std::lock_guard lock(mutex);
  if (level <= Level::Warn) std::fprintf(stderr, "[fovea-layer] %s: %s\n", name(level), buf);
  if (file) {
    std::fprintf(file, "%s: %s\n", name(level), buf);
    std::fflush(file);
  }
}

}  // namespace fovea::layer::log
