// --trace auto (renderer/trace_choice.hpp): a requested traversal is kept; without ray
// queries auto is the compute traversal; with them, both are measured once and the faster
// is taken, the measurement kept in the cache file that later choices read (a foreign or
// broken file is measured over).
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "fovea/renderer/trace_choice.hpp"
#include "gpu_fixture.hpp"

namespace fr = fovea::renderer;
namespace fs = std::filesystem;

namespace {

using TraceChoice = fovea::test::GpuTest;

TEST_F(TraceChoice, RequestedTraversalIsKeptAndNoRayQueriesMeansCompute) {
  const fr::TraceChoice compute = fr::choose_tracing(ctx(), fr::Tracing::Compute, "");
  EXPECT_EQ(compute.tracing, fr::Tracing::Compute);
  EXPECT_FALSE(compute.compute_ms.has_value());
  fovea::gpu::Context plain({.validation = true, .ray_query = false});
  const fr::TraceChoice none = fr::choose_tracing(plain, fr::Tracing::Auto, "");
  EXPECT_EQ(none.tracing, fr::Tracing::Compute);
  EXPECT_EQ(none.why, "the device has no ray queries");
}

TEST_F(TraceChoice, AutoMeasuresOnceAndTheCacheDecidesAfterwards) {
  if (!ctx().features().ray_query)
    GTEST_SKIP() << "the Vulkan device '" << ctx().info().name << "' (" << ctx().info().driver
                 << ") offers no ray queries: auto is the compute traversal without a measurement";
  const fs::path dir = fs::temp_directory_path() / ("fovea-trace-choice-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string cache = (dir / "sub" / "trace-choice.json").string();
  // Without measuring (the OpenXR layer) and nothing cached: ray queries, nothing written.
  const fr::TraceChoice unmeasured = fr::choose_tracing(ctx(), fr::Tracing::Auto, cache, false);
  EXPECT_EQ(unmeasured.tracing, fr::Tracing::RayQuery);
  EXPECT_FALSE(unmeasured.compute_ms.has_value());
  EXPECT_FALSE(fs::exists(cache));
  const fr::TraceChoice first = fr::choose_tracing(ctx(), fr::Tracing::Auto, cache);
  ASSERT_TRUE(first.compute_ms && first.rayquery_ms);
  EXPECT_GT(*first.compute_ms, 0.0);
  EXPECT_GT(*first.rayquery_ms, 0.0);
  EXPECT_FALSE(first.cached);
  EXPECT_EQ(first.tracing, *first.rayquery_ms < *first.compute_ms ? fr::Tracing::RayQuery : fr::Tracing::Compute);
  ASSERT_TRUE(fs::exists(cache));

  const fr::TraceChoice second = fr::choose_tracing(ctx(), fr::Tracing::Auto, cache);
  EXPECT_TRUE(second.cached);
  EXPECT_EQ(fr::choose_tracing(ctx(), fr::Tracing::Auto, cache, false).tracing, first.tracing)
      << "without measuring, the cached measurement decides";
  EXPECT_EQ(second.tracing, first.tracing);
  EXPECT_EQ(*second.compute_ms, *first.compute_ms);

  // The cache decides: its entry for this device, rewritten to say the other one is faster.
  nlohmann::json j = nlohmann::json::parse(std::ifstream(cache));
  ASSERT_EQ(j.size(), 1u);
  auto& e = j.begin().value();
  std::swap(e["compute_ms"], e["rayquery_ms"]);
  std::ofstream(cache) << j.dump();
  const fr::TraceChoice swapped = fr::choose_tracing(ctx(), fr::Tracing::Auto, cache);
  EXPECT_TRUE(swapped.cached);
  EXPECT_NE(swapped.tracing, first.tracing);

  // A broken file is measured over and replaced.
  std::ofstream(cache) << "{ not json";
  const fr::TraceChoice again = fr::choose_tracing(ctx(), fr::Tracing::Auto, cache);
  EXPECT_FALSE(again.cached);
  EXPECT_NE(again.why.find("was unreadable and is measured over"), std::string::npos) << again.why;
  EXPECT_TRUE(nlohmann::json::accept(std::ifstream(cache))) << "the replaced cache file is JSON";
  fs::remove_all(dir);
}

}  // namespace
