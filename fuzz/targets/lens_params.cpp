// Lens parameters on their own (a preset's "lens" object), without the preset checks
// that would otherwise reject most inputs first.
#include "../harness.hpp"
#include "fovea/core/lens_params.hpp"

FOVEA_FUZZ_TARGET(lens_params) { (void)fovea::core::parse_lens_params(fovea::fuzz::as_text(data), "fuzz-lens.json"); }
