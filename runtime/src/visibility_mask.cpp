#include "visibility_mask.hpp"

namespace fovea::runtime {

VisibilityMask visibility_mask(const core::HiddenAreaMask& hidden, XrVisibilityMaskTypeKHR type) {
  core::VisibilityMeshType t = core::VisibilityMeshType::HiddenTriangles;
  switch (type) {
    case XR_VISIBILITY_MASK_TYPE_VISIBLE_TRIANGLE_MESH_KHR: t = core::VisibilityMeshType::VisibleTriangles; break;
    case XR_VISIBILITY_MASK_TYPE_LINE_LOOP_KHR: t = core::VisibilityMeshType::LineLoop; break;
    default: break;
  }
  const core::VisibilityMesh mesh = core::visibility_mesh(hidden, t);
  VisibilityMask m;
  m.vertices.reserve(mesh.vertices.size());
  for (const glm::vec2& v : mesh.vertices) m.vertices.push_back({v.x, v.y});
  m.indices = mesh.indices;
  return m;
}

}  // namespace fovea::runtime
