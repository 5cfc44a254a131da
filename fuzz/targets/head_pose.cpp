// The simulated runtime's head-pose files (FOVEA_HEAD_POSE=<path>), then poses looked up
// before, inside and far after the recording.
#include "../harness.hpp"
#include "head_motion.hpp"

#include <limits>

FOVEA_FUZZ_TARGET(head_pose) {
  const auto h = fovea::runtime::HeadMotion::from_file(fovea::fuzz::scratch_file("head.txt", fovea::fuzz::as_text(data)));
  for (const fovea::core::TimeNs t : {std::numeric_limits<fovea::core::TimeNs>::min(), fovea::core::TimeNs(0),
                                      fovea::core::TimeNs(1'000'000'000), std::numeric_limits<fovea::core::TimeNs>::max()})
    (void)h.at(t);
}
