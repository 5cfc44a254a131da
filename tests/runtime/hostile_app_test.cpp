// The hostile application (hostile_app.hpp) against the Fovea runtime alone.
#include "hostile_app.hpp"

namespace fovea::test {

INSTANTIATE_TEST_SUITE_P(Runtime, HostileApp, ::testing::Values(HostileVariant{"alone", "", ""}),
                         [](const auto& info) { return info.param.name; });

}  // namespace fovea::test
