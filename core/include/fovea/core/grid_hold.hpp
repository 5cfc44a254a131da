#pragma once
// Where a foveated grid is laid out from frame to frame: at the gaze, and held there while the
// gaze stays within kHoldDeg of it. A fixating eye's drift and tremor stay within a few tenths
// of a degree; a held grid keeps its cells, and so their history. The fovea margin
// (DistributionParams::margin_deg, 1° by default) covers the offset: the hold is at most half
// the margin, so a held fovea still covers the gaze's own fovea with half the margin to spare
// for the tracker's error. A larger move (a microsaccade, pursuit, a saccade) lays the grid
// out again at the gaze. One per eye: the frame pipeline's grids and the latency harness's
// record of what they were laid out for.
#include <algorithm>

#include <glm/vec3.hpp>

namespace fovea::core {

class GridHold {
 public:
  static constexpr double kHoldDeg = 0.5;
  // The hold for a fovea margin: kHoldDeg, at most half the margin (none without one).
  static double radius_for_margin(double margin_deg) { return std::clamp(0.5 * margin_deg, 0.0, kHoldDeg); }
  explicit GridHold(double radius_deg = kHoldDeg) : radius_deg_(radius_deg) {}
  double radius_deg() const { return radius_deg_; }
  // The direction to lay this frame's grid out for, given the eye's gaze (view space). A
  // non-finite gaze passes through (the distribution's fallback decides) and holds nothing.
  glm::dvec3 place(const glm::dvec3& gaze);
  void reset() { held_ = {}; }

 private:
  double radius_deg_;
  glm::dvec3 held_{0, 0, 0};  // zero: nothing laid out yet
};

}  // namespace fovea::core
