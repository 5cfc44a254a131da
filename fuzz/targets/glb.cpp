// Binary glTF containers read from a file (chunk headers, the BIN chunk, external URIs
// resolved next to the file).
#include "../harness.hpp"
#include "../scene_limits.hpp"
#include "fovea/renderer/scene_io.hpp"

FOVEA_FUZZ_TARGET(glb) {
  (void)fovea::renderer::load_gltf(fovea::fuzz::scratch_file("fuzz.glb", fovea::fuzz::as_text(data)),
                                  fovea::fuzz::scene_limits());
}
