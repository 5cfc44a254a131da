// Replay of the pupil-core format (forced, so detection does not reject the input first).
#include "../gaze_options.hpp"
#include "../harness.hpp"

FOVEA_FUZZ_TARGET(gaze_pupil_core) {
  fovea::fuzz::drain_recording(fovea::fuzz::scratch_file("gaze_positions.csv", fovea::fuzz::as_text(data)), "pupil-core");
}
