#pragma once
// Bounding volume hierarchy over a triangle soup: binned surface-area-heuristic build on
// the CPU (subtrees built in parallel), collapsed to the compressed 4-wide 64-byte nodes the GPU
// traverses (shaders/include/fovea/shaders/pt_scene.h).
#include <cstdint>
#include <optional>
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
  // With an eye position, the tree is also built for a sample of the rays a path tracer
  // shoots (build_bvh) and the better of the two trees for those rays is kept.
  std::optional<glm::vec3> eye;
  int ray_samples = 8192;        // half from the eye, half from points on the triangles
};

struct Bvh {
  std::vector<shaders::PtBvhNode> nodes;  // nodes[0] is the root
  std::vector<std::uint32_t> order;       // order[i]: input triangle stored at slot i
  int depth = 0;                          // 4-wide levels, root = 1
  double sah_cost = 0;                    // SAH cost of the binary tree (for tests and reports)
  // With BvhOptions::eye: node visits + triangle tests per sample ray of the kept tree and
  // of the plain SAH tree, and whether the ray-guided tree was kept.
  double ray_cost = 0, sah_ray_cost = 0;
  bool ray_guided = false;
};

// `positions`: three vertices per triangle, all finite (scenes are sanitised first).
// Deterministic: the same input gives the same tree (the sample rays have a fixed seed).
Bvh build_bvh(std::span<const glm::vec3> positions, const BvhOptions& options = {});

}  // namespace fovea::renderer
