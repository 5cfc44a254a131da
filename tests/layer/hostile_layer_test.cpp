// The hostile application (tests/runtime/hostile_app.hpp) with XR_APILAYER_FOVEA_path_tracing
// between it and the runtime: passing through (no scene) and path tracing the Cornell box on
// the tiny display. Every error code is the runtime's, the process survives, and with a scene
// the layer is still rendering once the application behaves again.
#include <cstdlib>

#include "hostile_app.hpp"

namespace fovea::test {
namespace {

// Lockstep rendering: each frame the application ends shows the frame traced for its views, so
// "the layer is still rendering" holds for the last frame whatever the render thread's pace
// (the asynchronous mode is tested with pipelined frames in async_layer_test.cpp).
class LockstepRendering : public ::testing::Environment {
 public:
  void SetUp() override { setenv("FOVEA_LAYER_RENDER", "lockstep", 1); }
};
const auto* const kLockstep = ::testing::AddGlobalTestEnvironment(new LockstepRendering);

}  // namespace

INSTANTIATE_TEST_SUITE_P(Layer, HostileApp,
                         ::testing::Values(HostileVariant{"pass_through", FOVEA_LAYER_EXPLICIT_DIR, ""},
                                           HostileVariant{"cornell", FOVEA_LAYER_EXPLICIT_DIR, "cornell"}),
                         [](const auto& info) { return info.param.name; });

}  // namespace fovea::test
