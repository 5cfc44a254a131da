#pragma once
// Helpers for the devices tests: scratch files (plain or gzip) in a per-test temporary
// directory, and a stream read whole.
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fovea/devices/gaze.hpp"

namespace fovea::devices::test {

inline std::filesystem::path scratch_path(const ::testing::TestInfo& info) {
  return std::filesystem::temp_directory_path() /
         ("fovea_devices_" + std::to_string(::getpid()) + "_" + info.test_suite_name() + "_" + info.name());
}

inline std::string scratch_dir() {
  const std::filesystem::path d = scratch_path(*::testing::UnitTest::GetInstance()->current_test_info());
  std::filesystem::create_directories(d);
  return d.string();
}

// A passed test's scratch directory goes when it ends; a failed one's stays for a look.
class ScratchCleaner : public ::testing::EmptyTestEventListener {
  void OnTestEnd(const ::testing::TestInfo& info) override {
    if (!info.result()->Passed()) return;
    std::error_code ignored;
    std::filesystem::remove_all(scratch_path(info), ignored);
  }
};
inline const bool kScratchCleanerInstalled = [] {
  ::testing::UnitTest::GetInstance()->listeners().Append(new ScratchCleaner);
  return true;
}();

inline std::string write_text(const std::string& name, const std::string& text) {
  const std::string p = scratch_dir() + "/" + name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

// `text` gzip-compressed into a scratch file; `keep_bytes` truncates the file (a cut download).
inline std::string write_gz(const std::string& name, const std::string& text, std::size_t keep_bytes = SIZE_MAX) {
  const std::string p = scratch_dir() + "/" + name;
  gzFile g = gzopen(p.c_str(), "wb");
  gzwrite(g, text.data(), static_cast<unsigned>(text.size()));
  gzclose(g);
  if (keep_bytes != SIZE_MAX) std::filesystem::resize_file(p, keep_bytes);
  return p;
}

inline std::vector<GazeSample> read_all(SampleStream& r) {
  std::vector<GazeSample> v;
  GazeSample s;
  while (r.next(s)) v.push_back(s);
  return v;
}

inline std::string source_dir() {
  const char* s = std::getenv("FOVEA_SOURCE_DIR");
  return s ? s : ".";
}

}  // namespace fovea::devices::test
