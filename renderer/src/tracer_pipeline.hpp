#pragma once
// The pipeline of a tracer shader for a scene's tracing (PathTracer, Raycaster).
#include <cstdint>
#include <vector>

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

}  // namespace fovea::renderer
