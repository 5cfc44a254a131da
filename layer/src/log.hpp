#pragma once
// Layer diagnostics (xrcommon's logger): env FOVEA_LAYER_LOG_LEVEL (error|warn|info|debug,
// default info) selects what is logged; messages go to the file env FOVEA_LAYER_LOG_FILE (if
// set, opened at the first message) and, at warn or above, to stderr.
#include "fovea/xrcommon/log.hpp"

namespace fovea::layer::log {

using Level = xrcommon::LogLevel;
void write(Level level, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

}  // namespace fovea::layer::log

#define FOVEA_LAYER_ERROR(...) ::fovea::layer::log::write(::fovea::layer::log::Level::Error, __VA_ARGS__)
#define FOVEA_LAYER_WARN(...) ::fovea::layer::log::write(::fovea::layer::log::Level::Warn, __VA_ARGS__)
#define FOVEA_LAYER_INFO(...) ::fovea::layer::log::write(::fovea::layer::log::Level::Info, __VA_ARGS__)
#define FOVEA_LAYER_DEBUG(...) ::fovea::layer::log::write(::fovea::layer::log::Level::Debug, __VA_ARGS__)
