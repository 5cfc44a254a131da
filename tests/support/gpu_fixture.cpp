#include "gpu_fixture.hpp"

#include <exception>
#include <memory>
#include <string>

namespace fovea::test {
namespace {

struct Shared {
  std::unique_ptr<gpu::Context> context;
  std::exception_ptr failure;
  bool attempted = false;
};

Shared& shared() {
  static Shared s;
  return s;
}

// Destroys the shared context after the last test, so that errors raised while the
// device is destroyed (objects a test leaked) are reported instead of lost at exit.
class SharedContextEnvironment : public ::testing::Environment {
 public:
  void TearDown() override {
    Shared& s = shared();
    if (!s.context) return;
    const auto counters = s.context->validation_counters();
    const std::int64_t before = counters->errors.load();
    s.context.reset();
    const std::int64_t raised = counters->errors.load() - before;
    if (raised != 0) ADD_FAILURE() << raised << " Vulkan validation error(s) while destroying the shared device "
                                   << "(a test leaked Vulkan objects?); see the messages above";
  }
};

[[maybe_unused]] ::testing::Environment* const environment =
    ::testing::AddGlobalTestEnvironment(new SharedContextEnvironment);

}  // namespace

gpu::Context& shared_context() {
  Shared& s = shared();
  if (!s.attempted) {
    s.attempted = true;
    try {
      gpu::ContextOptions options;
      options.validation = true;  // GPU tests always run validated
      s.context = std::make_unique<gpu::Context>(options);
    } catch (...) {
      s.failure = std::current_exception();
    }
  }
  if (s.failure) std::rethrow_exception(s.failure);
  return *s.context;
}

void GpuTest::SetUp() {
  try {
    ctx_ = &shared_context();
  } catch (const std::exception& e) {
    FAIL() << "cannot create the validated Vulkan context for GPU tests: " << e.what();
  }
  errors_at_start_ = ctx_->validation_errors();
}

void GpuTest::TearDown() {
  if (ctx_ == nullptr) return;
  const std::int64_t unexpected = ctx_->validation_errors() - errors_at_start_ - expected_errors_;
  EXPECT_EQ(unexpected, 0) << "Vulkan validation errors during the test; see the messages above";
}

}  // namespace fovea::test
