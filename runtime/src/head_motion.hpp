#pragma once
// The simulated head: the VIEW space's pose in LOCAL space as a function of time since the
// display epoch. Either a slow deterministic script (default), a fixed pose, or samples read
// from a text file (env FOVEA_HEAD_POSE=scripted|static|<path>).
#include <string>
#include <vector>

#include "fovea/core/clock.hpp"
#include "fovea/core/view.hpp"

namespace fovea::runtime {

class HeadMotion {
 public:
  // Slow sinusoids: yaw ±10° over 8 s, pitch ±5° over 11 s, a few centimetres of sway.
  static HeadMotion scripted();
  static HeadMotion stationary();
  // Lines "t_s px py pz qx qy qz qw" (seconds since the display epoch, metres, unit
  // quaternion), '#' starts a comment; times strictly increasing. Linear / spherical
  // interpolation between samples, held constant outside. Throws core::InputError naming
  // path:line.
  static HeadMotion from_file(const std::string& path);
  // "scripted", "static" or a path.
  static HeadMotion from_spec(const std::string& spec);

  core::Pose at(core::TimeNs since_epoch) const;

 private:
  enum class Kind { Scripted, Static, Samples } kind_ = Kind::Static;
  struct Sample {
    double t;
    core::Pose pose;
  };
  std::vector<Sample> samples_;
};

}  // namespace fovea::runtime
