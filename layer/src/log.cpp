#include "log.hpp"

#include <algorithm>
#include <cstdlib>

namespace fovea::layer::log {
namespace {

struct LayerLogger {
  xrcommon::Logger logger;
  LayerLogger() : LayerLogger(xrcommon::log_level_from_env("FOVEA_LAYER_LOG_LEVEL", Level::Info)) {}
  explicit LayerLogger(Level max) : logger("[fovea-layer]", std::min(max, Level::Warn), max) {
    const char* path = std::getenv("FOVEA_LAYER_LOG_FILE");
    // The layer keeps working without the file; the messages still reach stderr from warn up.
    if (path && *path) logger.open(path, "FOVEA_LAYER_LOG_FILE", Level::Warn);
  }
};

}  // namespace

void write(Level level, const char* fmt, ...) {
  static LayerLogger log;
  va_list ap;
  va_start(ap, fmt);
  log.logger.vwrite(level, fmt, ap);
  va_end(ap);
}

}  // namespace fovea::layer::log
