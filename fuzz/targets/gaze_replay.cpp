// A recording in any format, plain or gzip, auto-detected, then replayed through the
// timeline as the renderer does (looping, interpolation, clamping at both ends).
#include <limits>

#include "../gaze_options.hpp"
#include "../harness.hpp"

FOVEA_FUZZ_TARGET(gaze_replay) {
  const std::string path = fovea::fuzz::scratch_file("recording", fovea::fuzz::as_text(data));
  fovea::fuzz::drain_recording(path, "");
  const auto src = fovea::devices::open_gaze_source("replay:" + path + "?loop=1", fovea::fuzz::gaze_options());
  for (const fovea::core::TimeNs t : {fovea::core::TimeNs(0), fovea::core::TimeNs(16'000'000),
                                      fovea::core::TimeNs(3'000'000'000), std::numeric_limits<fovea::core::TimeNs>::max()})
    (void)src->sample_at(t);
  (void)src->latest();
}
