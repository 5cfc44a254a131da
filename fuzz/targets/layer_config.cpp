// The OpenXR layer's layer.json (compiled in: the layer library exports only its
// OpenXR entry points).
#include "../harness.hpp"
#include "config.hpp"

FOVEA_FUZZ_TARGET(layer_config) {
  (void)fovea::layer::parse_config(std::string(fovea::fuzz::as_text(data)), "layer.json", "App");
}
