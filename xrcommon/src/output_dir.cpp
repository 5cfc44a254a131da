#include "fovea/xrcommon/output_dir.hpp"

#include <filesystem>
#include <system_error>

#include "fovea/core/error.hpp"

namespace fovea::xrcommon {

void create_output_dir(const std::string& dir, const char* variable) {
  if (dir.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw core::InputError(std::string(variable) + "=" + dir + ": cannot create the directory: " +
                           (ec ? ec.message() : "a file of that name exists"));
}

}  // namespace fovea::xrcommon
