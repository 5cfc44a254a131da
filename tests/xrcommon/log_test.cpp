// The shared leveled logger: thresholds per destination, line formats, environment levels,
// an unopenable file reported with what named it.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "fovea/xrcommon/log.hpp"

namespace fovea::xrcommon {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

fs::path temp_file(const char* name) {
  const fs::path p = fs::temp_directory_path() / (std::string("fovea_log_test_") + name + "_" + std::to_string(::getpid()));
  fs::remove(p);
  return p;
}

TEST(Logger, EachDestinationHasItsOwnThreshold) {
  const fs::path file = temp_file("levels");
  Logger log("[tag]", LogLevel::Warn, LogLevel::Info);
  ASSERT_TRUE(log.open(file.string(), "TEST_FILE", LogLevel::Warn));
  testing::internal::CaptureStderr();
  log.write(LogLevel::Error, "e %d", 1);
  log.write(LogLevel::Warn, "w %s", "two");
  log.write(LogLevel::Info, "i");
  log.write(LogLevel::Debug, "d");
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(err, "[tag] error: e 1\n[tag] warn: w two\n");
  EXPECT_EQ(read_text(file), "error: e 1\nwarn: w two\ninfo: i\n");
  // Appending: a second logger adds to the same file.
  {
    Logger again("[tag]", LogLevel::Error, LogLevel::Debug);
    ASSERT_TRUE(again.open(file.string(), "TEST_FILE", LogLevel::Warn));
    again.write(LogLevel::Debug, "d2");
  }
  EXPECT_EQ(read_text(file), "error: e 1\nwarn: w two\ninfo: i\ndebug: d2\n");
  fs::remove(file);
}

TEST(Logger, WithoutFileOnlyStderr) {
  Logger log("[x]", LogLevel::Info, LogLevel::Debug);
  testing::internal::CaptureStderr();
  log.write(LogLevel::Info, "hello");
  log.write(LogLevel::Debug, "hidden");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "[x] info: hello\n");
}

TEST(Logger, UnopenableFileIsReportedWithItsNameAndReason) {
  Logger log("[tag]", LogLevel::Warn, LogLevel::Debug);
  testing::internal::CaptureStderr();
  EXPECT_FALSE(log.open("/nonexistent-fovea-dir/x.log", "TEST_LOG_FILE", LogLevel::Error));
  log.write(LogLevel::Warn, "still here");
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("[tag] error: cannot open TEST_LOG_FILE \"/nonexistent-fovea-dir/x.log\": No such file"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("[tag] warn: still here\n"), std::string::npos) << err;
}

TEST(Logger, LevelFromEnvironment) {
  unsetenv("FOVEA_TEST_LOG_LEVEL");
  EXPECT_EQ(log_level_from_env("FOVEA_TEST_LOG_LEVEL", LogLevel::Warn), LogLevel::Warn);
  const std::pair<const char*, LogLevel> cases[] = {
      {"error", LogLevel::Error}, {"warn", LogLevel::Warn}, {"info", LogLevel::Info}, {"debug", LogLevel::Debug}};
  for (const auto& [name, level] : cases) {
    setenv("FOVEA_TEST_LOG_LEVEL", name, 1);
    EXPECT_EQ(log_level_from_env("FOVEA_TEST_LOG_LEVEL", LogLevel::Info), level) << name;
    EXPECT_STREQ(log_level_name(level), name);
  }
  setenv("FOVEA_TEST_LOG_LEVEL", "verbose", 1);
  EXPECT_EQ(log_level_from_env("FOVEA_TEST_LOG_LEVEL", LogLevel::Info), LogLevel::Info);
  unsetenv("FOVEA_TEST_LOG_LEVEL");
}

}  // namespace
}  // namespace fovea::xrcommon
