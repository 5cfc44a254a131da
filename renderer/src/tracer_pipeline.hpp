#pragma once
// The pipeline of a tracer shader for a scene's tracing (PathTracer, Raycaster).
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include "fovea/core/error.hpp"
#include "fovea/core/view.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/renderer/gpu_scene.hpp"
#include "fovea/shaders/pt_bindings.h"

namespace fovea::renderer {

// `shader` (e.g. "pt_trace") as <shader>.comp.spv, or <shader>.rayquery.comp.spv with set 1
// = the acceleration structure (GpuScene::ray_query_set()) when the scene ray queries; set 0
// as given; `specialization` for both variants, plus the traversal stack's constants
// (kPtSpecBvhStack, kPtSpecSharedBytes).
gpu::ComputePipelineDesc tracer_pipeline(const GpuScene& scene, const char* shader, std::vector<gpu::Binding> set0,
                                         std::uint32_t push_constant_bytes,
                                         std::vector<gpu::SpecConstant> specialization = {});

// The eye pose of `view` in a tracer's push constants (the view-to-world rotation's columns
// rot0..rot2 and the position origin_*); core::InputError naming `what` when not finite.
template <class Params>
void set_eye_pose(Params& p, const core::View& view, const char* what) {
  const glm::dmat3 r = glm::mat3_cast(view.pose().orientation);
  const glm::dvec3 o = view.pose().position;
  if (!std::isfinite(o.x) || !std::isfinite(o.y) || !std::isfinite(o.z) || !std::isfinite(r[0][0]))
    throw core::InputError(std::string(what) + ": non-finite eye pose");
  p.rot0_x = float(r[0].x), p.rot0_y = float(r[0].y), p.rot0_z = float(r[0].z);
  p.rot1_x = float(r[1].x), p.rot1_y = float(r[1].y), p.rot1_z = float(r[1].z);
  p.rot2_x = float(r[2].x), p.rot2_y = float(r[2].y), p.rot2_z = float(r[2].z);
  p.origin_x = float(o.x), p.origin_y = float(o.y), p.origin_z = float(o.z);
}

}  // namespace fovea::renderer
