#pragma once
// Bounding volume hierarchy over a triangle soup: binned surface-area-heuristic build on
// the CPU (subtrees built in parallel), collapsed to the compressed 4-wide 64-byte nodes the GPU
// traverses (shaders/include/fovea/shaders/pt_scene.h).
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "fovea/shaders/pt_scene.h"

namespace fovea::renderer {

struct BvhOptions {
  int bins = 16;                 // SAH bins per axis
  int max_leaf = 8;              // leaves never hold more (unless the depth limit forces it)
  float traversal_cost = 1.0f;   // SAH cost of a node visit relative to a triangle test
  int threads = 0;               // 0: std::thread::hardware_concurrency()
};

struct Bvh {
  std::vector<shaders::PtBvhNode> nodes;  // nodes[0] is the root
  std::vector<std::uint32_t> order;       // order[i]: input triangle stored at slot i
  int depth = 0;                          // 4-wide levels, root = 1
  double sah_cost = 0;                    // SAH cost of the binary tree (for tests and reports)
};

// `positions`: three vertices per triangle, all finite (scenes are sanitised first).
Bvh build_bvh(std::span<const glm::vec3> positions, const BvhOptions& options = {});

}  // namespace fovea::renderer
