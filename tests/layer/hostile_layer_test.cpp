// The hostile application (tests/runtime/hostile_app.hpp) with XR_APILAYER_FOVEA_path_tracing
// between it and the runtime: passing through (no scene) and path tracing the Cornell box on
// the tiny display. Every error code is the runtime's, the process survives, and with a scene
// the layer is still rendering once the application behaves again.
#include "hostile_app.hpp"

namespace fovea::test {

INSTANTIATE_TEST_SUITE_P(Layer, HostileApp,
                         ::testing::Values(HostileVariant{"pass_through", FOVEA_LAYER_EXPLICIT_DIR, ""},
                                           HostileVariant{"cornell", FOVEA_LAYER_EXPLICIT_DIR, "cornell"}),
                         [](const auto& info) { return info.param.name; });

}  // namespace fovea::test
