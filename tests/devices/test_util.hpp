#pragma once
// Helpers for the devices tests: scratch files in a per-test temporary directory.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace fovea::devices::test {

inline std::string scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path d = std::filesystem::temp_directory_path() /
                                  ("fovea_devices_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
  std::filesystem::create_directories(d);
  return d.string();
}

inline std::string write_text(const std::string& name, const std::string& text) {
  const std::string p = scratch_dir() + "/" + name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

inline std::string source_dir() {
  const char* s = std::getenv("FOVEA_SOURCE_DIR");
  return s ? s : ".";
}

}  // namespace fovea::devices::test
