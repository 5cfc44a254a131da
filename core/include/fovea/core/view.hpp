#pragma once
// One eye's view: OpenXR-style field of view (four half-angles, asymmetric allowed),
// pose, and the display raster. View space follows OpenXR: -Z forward, +Y up, +X right.
// Pixels: origin at the top-left corner, y down, pixel (i, j) has its centre at (i+0.5, j+0.5).
#include <optional>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace fovea::core {

// Half-angles in radians, as XrFovf: left and down are usually negative.
struct Fov {
  double angle_left = 0, angle_right = 0, angle_up = 0, angle_down = 0;

  static Fov from_degrees(double left, double right, double up, double down);
  // The same field of view seen by the other eye (left/right swapped and negated).
  Fov mirrored() const;
};

struct Pose {
  glm::dquat orientation{1, 0, 0, 0};
  glm::dvec3 position{0, 0, 0};
};

class View {
 public:
  View() = default;
  // Throws InputError for non-finite angles, an empty/inverted FOV, half-angles of 90°
  // or more, or a raster smaller than 1×1.
  View(const Fov& fov, int width, int height, const Pose& pose = {});

  const Fov& fov() const { return fov_; }
  const Pose& pose() const { return pose_; }
  int width() const { return width_; }
  int height() const { return height_; }

  // Tangent-plane extents: x in [tan_left, tan_right], y in [tan_down, tan_up] at z = -1.
  double tan_left() const { return tl_; }
  double tan_right() const { return tr_; }
  double tan_up() const { return tu_; }
  double tan_down() const { return td_; }

  // Continuous pixel position -> unit view-space direction (any position, also off-screen).
  glm::dvec3 pixel_to_dir(glm::dvec2 px) const;
  // Unit (or any non-zero) view-space direction -> continuous pixel position; nullopt if
  // the direction does not point into the front half-space (z >= 0) or is not finite.
  std::optional<glm::dvec2> dir_to_pixel(glm::dvec3 dir) const;
  // On the raster, or within `margin` pixels outside it.
  bool contains_pixel(glm::dvec2 px, double margin = 0) const {
    return px.x >= -margin && px.y >= -margin && px.x <= width_ + margin && px.y <= height_ + margin;
  }
  // Direction through the centre of the raster.
  glm::dvec3 centre_dir() const;
  // Display pixels per square degree at a view direction (tangent-plane projection).
  double pixels_per_deg2(glm::dvec3 dir) const;
  // Unit directions of the four frustum corners (top-left, top-right, bottom-right, bottom-left).
  void corner_dirs(glm::dvec3 out[4]) const;
  // Clamp a direction to the frustum (in tangent space). Returns false if the input is
  // not usable at all (zero, NaN, or pointing backwards where no clamp is meaningful).
  bool clamp_to_frustum(glm::dvec3& dir) const;

 private:
  Fov fov_{};
  Pose pose_{};
  int width_ = 1, height_ = 1;
  double tl_ = -1, tr_ = 1, tu_ = 1, td_ = -1;
};

// Angle in degrees between two unit vectors, accurate also for tiny and near-180° angles
// (atan2 of |a×b| and a·b instead of acos of a·b).
double angle_deg(glm::dvec3 a, glm::dvec3 b);

}  // namespace fovea::core
