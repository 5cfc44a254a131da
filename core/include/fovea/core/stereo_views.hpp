#pragma once
// What a stereo frame is rendered for: per eye the field of view, raster and world pose,
// and the interpupillary distance. The pipeline's input; the CLI builds it from a display
// preset (stereo_views), the OpenXR layer from the views the application submits.
#include <array>

#include "fovea/core/display.hpp"
#include "fovea/core/view.hpp"

namespace fovea::core {

struct StereoViews {
  std::array<View, 2> eye;  // indexed by Eye
  double ipd_m = 0;

  const View& operator[](Eye e) const { return eye[std::size_t(e)]; }
  std::array<Pose, 2> poses() const { return {eye[0].pose(), eye[1].pose()}; }
};

// The eye poses of a head: each eye ipd/2 beside `head` along the head's x axis, turned
// outwards by `cant_deg` about its y axis (DisplayPreset::cant_deg).
std::array<Pose, 2> eye_poses(const Pose& head, double ipd_m, double cant_deg);
std::array<Pose, 2> eye_poses(const Pose& head, const DisplayPreset& d);
// The preset's per-eye FOV and raster with the eyes of `head` (eye_poses, the preset's IPD and cant).
StereoViews stereo_views(const DisplayPreset& d, const Pose& head = {});

}  // namespace fovea::core
