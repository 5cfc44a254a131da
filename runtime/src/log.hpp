#pragma once
// Runtime diagnostics (xrcommon's logger): stderr at the level of env FOVEA_RUNTIME_LOG
// (error|warn|info|debug, default warn) and, when env FOVEA_RUNTIME_OUT is set, every message
// at info level or above in <out>/runtime.log (the tests read it).
#include <string>

#include "fovea/xrcommon/log.hpp"

namespace fovea::runtime::log {

using Level = xrcommon::LogLevel;

// Opens <dir>/runtime.log (appending) for the process; empty dir closes it.
void set_file_dir(const std::string& dir);
void write(Level level, const char* fmt, ...) __attribute__((format(printf, 2, 3)));

}  // namespace fovea::runtime::log

#define FOVEA_LOG_ERROR(...) ::fovea::runtime::log::write(::fovea::runtime::log::Level::Error, __VA_ARGS__)
#define FOVEA_LOG_WARN(...) ::fovea::runtime::log::write(::fovea::runtime::log::Level::Warn, __VA_ARGS__)
#define FOVEA_LOG_INFO(...) ::fovea::runtime::log::write(::fovea::runtime::log::Level::Info, __VA_ARGS__)
#define FOVEA_LOG_DEBUG(...) ::fovea::runtime::log::write(::fovea::runtime::log::Level::Debug, __VA_ARGS__)
