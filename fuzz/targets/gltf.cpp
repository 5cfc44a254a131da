// glTF 2.0 text from memory (data URIs only): tinygltf's parse, the loader's checks,
// texture decoding, the node-graph walk.
#include "../harness.hpp"
#include "../scene_limits.hpp"
#include "fovea/renderer/scene_io.hpp"

FOVEA_FUZZ_TARGET(gltf) {
  (void)fovea::renderer::load_gltf_text(fovea::fuzz::as_text(data), "fuzz.gltf", "", fovea::fuzz::scene_limits());
}
