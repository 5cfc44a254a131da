#pragma once
// The output directory of the runtime (FOVEA_RUNTIME_OUT) and of the API layer
// (FOVEA_LAYER_OUT): created with its parents, so a first frame never fails on a missing one.
#include <string>

namespace fovea::xrcommon {

// Creates `dir` and its parents if missing (nothing for an empty `dir`). Throws
// core::InputError naming `variable`=dir and the reason when it cannot, or when a file of
// that name is in the way.
void create_output_dir(const std::string& dir, const char* variable);

}  // namespace fovea::xrcommon
