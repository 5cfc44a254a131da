// Wavefront OBJ plus one material library: the input up to a line "#mtl" is the OBJ
// (written as fuzz.obj), the rest fuzz.mtl next to it, so `mtllib fuzz.mtl` reaches it.
#include "../harness.hpp"
#include "../scene_limits.hpp"
#include "fovea/renderer/scene_io.hpp"

FOVEA_FUZZ_TARGET(obj) {
  const auto [obj, mtl] = fovea::fuzz::split(fovea::fuzz::as_text(data), "\n#mtl\n");
  fovea::fuzz::scratch_file("fuzz.mtl", mtl);
  (void)fovea::renderer::load_obj(fovea::fuzz::scratch_file("fuzz.obj", obj), fovea::fuzz::scene_limits());
}
