#include "log.hpp"

namespace fovea::runtime::log {
namespace {

xrcommon::Logger& logger() {
  static xrcommon::Logger l("[fovea-runtime]", xrcommon::log_level_from_env("FOVEA_RUNTIME_LOG", Level::Warn),
                            Level::Info);
  return l;
}

}  // namespace

void set_file_dir(const std::string& dir) {
  logger().open(dir.empty() ? dir : dir + "/runtime.log", "the runtime log", Level::Error);
}

void write(Level level, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  logger().vwrite(level, fmt, ap);
  va_end(ap);
}

}  // namespace fovea::runtime::log
