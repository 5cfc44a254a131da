#pragma once
// --gaze X,Y (normalised screen coordinates, origin top-left) or --gaze-dir x,y,z.
#include <glm/vec3.hpp>

#include "command.hpp"
#include "fovea/core/view.hpp"

namespace fovea::tools {

glm::dvec3 parse_gaze(const Args& a, const core::View& view);

}  // namespace fovea::tools
