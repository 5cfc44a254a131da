// The layer's timing log, layer_timing.jsonl, in one process through the OpenXR loader: what
// it holds over several sessions and on which clock.
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fovea/core/json.hpp"
#include "xr_fixture.hpp"
#include "xr_process.hpp"

namespace fovea::test {
namespace {

constexpr const char* kFoveaLayer = "XR_APILAYER_FOVEA_path_tracing";

class LayerLogTest : public XrTest {
 protected:
  void SetUp() override {
    XrTest::SetUp();
    out_ = std::make_unique<TempDir>("layer_log");
    setenv("XR_API_LAYER_PATH", FOVEA_LAYER_EXPLICIT_DIR, 1);
    setenv("XR_ENABLE_API_LAYERS", kFoveaLayer, 1);
    setenv("FOVEA_LAYER_OUT", out_->path().c_str(), 1);
  }
  void TearDown() override {
    XrTest::TearDown();
    for (const char* v : {"XR_API_LAYER_PATH", "XR_ENABLE_API_LAYERS", "FOVEA_LAYER_OUT"}) unsetenv(v);
  }
  std::vector<nlohmann::json> records() const {
    std::vector<nlohmann::json> v;
    std::ifstream in(out_->path() + "/layer_timing.jsonl");
    for (std::string line; std::getline(in, line);) v.push_back(core::parse_json(line));
    return v;
  }
  std::unique_ptr<TempDir> out_;
};

// Two sessions of one process (one after the other, each on its own instance) keep their
// records in the one file, each record naming its session; the second session no longer
// truncates the first one's records.
TEST_F(LayerLogTest, EverySessionOfTheProcessIsKept) {
  constexpr int kFrames[2] = {3, 2};
  for (const int frames : kFrames) {
    ASSERT_NO_FATAL_FAILURE(create_instance());
    ASSERT_NO_FATAL_FAILURE(run_to_focused());
    for (int f = 1; f < frames; ++f) ASSERT_EQ(frame(), XR_SUCCESS);
    end_instance();
  }
  const std::vector<nlohmann::json> r = records();
  ASSERT_EQ(r.size(), std::size_t(kFrames[0] + kFrames[1]));
  std::map<std::int64_t, std::vector<std::int64_t>> frames_of;  // session -> its frames, in file order
  for (const auto& rec : r) {
    ASSERT_TRUE(rec.contains("session") && rec["session"].is_number_integer()) << rec.dump();
    frames_of[rec["session"].get<std::int64_t>()].push_back(rec["frame"].get<std::int64_t>());
  }
  ASSERT_EQ(frames_of.size(), 2u);
  const std::int64_t first = frames_of.begin()->first;
  EXPECT_EQ(frames_of.rbegin()->first, first + 1) << "sessions numbered in creation order";
  EXPECT_EQ(frames_of[first], (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_EQ(frames_of[first + 1], (std::vector<std::int64_t>{0, 1}));
  EXPECT_EQ(r.front()["session"], first) << "the first session's records come first";
}

}  // namespace
}  // namespace fovea::test
