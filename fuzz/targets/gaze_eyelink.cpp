// Replay of the eyelink-asc format (forced, so detection does not reject the input first).
#include "../gaze_options.hpp"
#include "../harness.hpp"

FOVEA_FUZZ_TARGET(gaze_eyelink) {
  fovea::fuzz::drain_recording(fovea::fuzz::scratch_file("fuzz.asc", fovea::fuzz::as_text(data)), "eyelink-asc");
}
