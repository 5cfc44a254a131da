#include "fovea/compositor/reconstruct.hpp"

#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include "fovea/core/error.hpp"

namespace fovea::compositor {

Denoiser parse_denoiser(std::string_view s) {
  if (s == "bmfr") return Denoiser::Bmfr;
  if (s == "none") return Denoiser::None;
  throw core::InputError("--denoiser: unknown \"" + std::string(s) + "\" (expected bmfr|none)");
}

StereoShare parse_stereo_share(std::string_view s) {
  if (s == "off") return StereoShare::Off;
  if (s == "gather") return StereoShare::Gather;
  if (s == "alternate") return StereoShare::Alternate;
  throw core::InputError("--stereo-share: unknown \"" + std::string(s) + "\" (expected off|gather|alternate)");
}

const char* denoiser_name(Denoiser d) { return d == Denoiser::Bmfr ? "bmfr" : "none"; }

const char* stereo_share_name(StereoShare s) {
  switch (s) {
    case StereoShare::Gather: return "gather";
    case StereoShare::Alternate: return "alternate";
    default: return "off";
  }
}

shaders::ReconGrid recon_grid(const core::SampleDistribution& d, const core::Pose& pose, std::uint32_t table_offset) {
  shaders::ReconGrid r{};
  r.g = d.gpu_params();
  // World-to-view rotation = transpose of the view-to-world rotation: its rows are the
  // view axes in world space.
  const glm::dmat3 v2w = glm::mat3_cast(pose.orientation);
  const glm::dvec3 x = v2w[0], y = v2w[1], z = v2w[2];
  r.w2v0_x = float(x.x), r.w2v0_y = float(x.y), r.w2v0_z = float(x.z);
  r.w2v1_x = float(y.x), r.w2v1_y = float(y.y), r.w2v1_z = float(y.z);
  r.w2v2_x = float(z.x), r.w2v2_y = float(z.y), r.w2v2_z = float(z.z);
  r.eye_x = float(pose.position.x), r.eye_y = float(pose.position.y), r.eye_z = float(pose.position.z);
  r.table_offset = table_offset;
  r.valid = 1;
  return r;
}

glm::ivec2 bmfr_block_offset(std::uint32_t frame) {
  // A 4×4 stratification of [0, 32)² (one offset per 8×8 stratum, visited in a shuffled
  // order with fixed sub-stratum positions): uniform over all offsets and fixed.
  static constexpr int kOrder[16] = {5, 14, 3, 8, 11, 0, 13, 6, 2, 9, 15, 4, 10, 7, 1, 12};
  static constexpr int kJitter[16][2] = {{3, 5}, {6, 1}, {1, 6}, {4, 3}, {7, 7}, {2, 2}, {5, 4}, {0, 0},
                                         {6, 5}, {3, 1}, {1, 3}, {5, 7}, {2, 6}, {7, 2}, {4, 0}, {0, 4}};
  const int s = kOrder[frame % 16];
  return {(s % 4) * 8 + kJitter[s][0], (s / 4) * 8 + kJitter[s][1]};
}

}  // namespace fovea::compositor
