// Replay of the tobii-g3 format (forced, so detection does not reject the input first).
#include "../gaze_options.hpp"
#include "../harness.hpp"

FOVEA_FUZZ_TARGET(gaze_tobii) {
  fovea::fuzz::drain_recording(fovea::fuzz::scratch_file("gazedata", fovea::fuzz::as_text(data)), "tobii-g3");
}
