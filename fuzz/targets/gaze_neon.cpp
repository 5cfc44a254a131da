// Replay of the neon format (forced, so detection does not reject the input first).
#include "../gaze_options.hpp"
#include "../harness.hpp"

FOVEA_FUZZ_TARGET(gaze_neon) {
  fovea::fuzz::drain_recording(fovea::fuzz::scratch_file("gaze.csv", fovea::fuzz::as_text(data)), "neon");
}
