#pragma once
// The GGX specular albedo table the path tracer's layered BSDF reads (layout:
// shaders/include/fovea/shaders/pt_scene.h, kPtGgxTableSize).
#include <vector>

#include <glm/vec4.hpp>

namespace fovea::renderer {

// kPtGgxTableSize² entries (A, B, A_avg, B_avg), computed once per process by stratified
// visible-normal sampling with the same microfacet model as pt_sampling.h.
const std::vector<glm::vec4>& ggx_albedo_table();

}  // namespace fovea::renderer
