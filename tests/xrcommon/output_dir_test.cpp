// The output directory helper the runtime (FOVEA_RUNTIME_OUT) and the layer (FOVEA_LAYER_OUT) share.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "fovea/core/error.hpp"
#include "fovea/xrcommon/output_dir.hpp"

namespace fovea::xrcommon {
namespace {

namespace fs = std::filesystem;

TEST(OutputDir, CreatedWithItsParentsOrRefusedNamingTheVariable) {
  const fs::path root = fs::temp_directory_path() / ("fovea_output_dir_" + std::to_string(::getpid()));
  fs::remove_all(root);
  const fs::path nested = root / "not" / "yet" / "there";
  create_output_dir(nested.string(), "FOVEA_LAYER_OUT");
  EXPECT_TRUE(fs::is_directory(nested));
  create_output_dir(nested.string(), "FOVEA_LAYER_OUT");  // existing: nothing to do
  create_output_dir("", "FOVEA_LAYER_OUT");               // unset: nothing to do
  std::ofstream(root / "a_file") << "x";
  for (const fs::path& bad : {root / "a_file", root / "a_file" / "sub"}) {
    try {
      create_output_dir(bad.string(), "FOVEA_RUNTIME_OUT");
      ADD_FAILURE() << "no error for " << bad;
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("FOVEA_RUNTIME_OUT=" + bad.string() + ": cannot create the directory"),
                std::string::npos)
          << e.what();
    }
  }
  fs::remove_all(root);
}

}  // namespace
}  // namespace fovea::xrcommon
