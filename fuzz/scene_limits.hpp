#pragma once
// The scene harnesses' limits: the loaders' defaults scaled down so that inputs near a
// limit (a node graph walked a million times, a 512 MiB texture) stay fast enough to
// fuzz; the same checks run, only the thresholds are lower.
#include "fovea/renderer/scene.hpp"

namespace fovea::fuzz {

inline renderer::SceneLimits scene_limits() {
  renderer::SceneLimits l;
  l.max_triangles = 200'000;
  l.max_node_instances = 20'000;
  l.max_texture_bytes = std::size_t(64) << 20;
  l.max_file_bytes = std::size_t(64) << 20;
  return l;
}

}  // namespace fovea::fuzz
