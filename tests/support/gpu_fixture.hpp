#pragma once
// GoogleTest fixture for GPU tests. All tests of a binary share one gpu::Context created
// on first use with the Khronos validation layer forced on (a missing layer fails the
// test with the reason). A test fails when the validation error counter grew during it,
// except for errors announced with expect_validation_errors. After the last test the
// context is destroyed and errors reported during device destruction (leaked objects)
// fail the run.
#include <cstdint>
#include <utility>

#include <gtest/gtest.h>

#include "fovea/gpu/context.hpp"

namespace fovea::test {

// The shared context; throws what Context's constructor threw, on every call.
gpu::Context& shared_context();

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;

  gpu::Context& ctx() { return *ctx_; }

  // Runs `fn` and expects it to raise exactly `count` validation errors, which then
  // do not fail the test. For negative tests only.
  template <class F>
  void expect_validation_errors(std::int64_t count, F&& fn) {
    const std::int64_t before = ctx_->validation_errors();
    std::forward<F>(fn)();
    const std::int64_t raised = ctx_->validation_errors() - before;
    EXPECT_EQ(raised, count) << "validation errors raised by the negative test";
    expected_errors_ += raised;
  }

 private:
  gpu::Context* ctx_ = nullptr;
  std::int64_t errors_at_start_ = 0;
  std::int64_t expected_errors_ = 0;
};

}  // namespace fovea::test
