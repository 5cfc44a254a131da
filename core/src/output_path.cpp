#include "fovea/core/output_path.hpp"

#include <unistd.h>

#include <filesystem>
#include <system_error>

#include "fovea/core/error.hpp"

namespace fovea::core {

namespace fs = std::filesystem;

namespace {
[[noreturn]] void refuse(std::string_view option, const std::string& path, const std::string& why) {
  throw InputError(std::string(option) + " \"" + path + "\": " + why);
}
}  // namespace

void prepare_output_dir(const std::string& path, std::string_view option) {
  if (path.empty()) refuse(option, path, "empty path");
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (fs::exists(st) && !fs::is_directory(st)) refuse(option, path, "exists and is not a directory");
  if (!fs::exists(st)) {
    fs::create_directories(path, ec);
    if (ec) refuse(option, path, "cannot create the directory: " + ec.message());
  }
  if (::access(path.c_str(), W_OK | X_OK) != 0) refuse(option, path, "the directory is not writable");
}

void prepare_output_file(const std::string& path, std::string_view option) {
  if (path.empty()) refuse(option, path, "empty path");
  std::error_code ec;
  if (fs::is_directory(path, ec)) refuse(option, path, "is a directory, expected a file name");
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) prepare_output_dir(parent.string(), option);
}

}  // namespace fovea::core
