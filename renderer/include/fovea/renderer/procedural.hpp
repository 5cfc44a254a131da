#pragma once
// Built-in scenes, generated in code (metres, +Y up).
#include "fovea/renderer/scene.hpp"

namespace fovea::renderer {

// The measured Cornell box (Cornell University Program of Computer Graphics data,
// millimetres scaled to metres), area light in the ceiling. `mirrored` reflects it
// about its centre plane x = const (red/green walls and blocks swap sides) and
// mirrors the camera, for symmetry tests.
Scene make_cornell(bool mirrored = false);
// Closed diffuse sphere (albedo 0.5, emission 1 everywhere, pure Lambert), viewer at
// its centre: radiance is 1/(1−0.5) = 2 in every direction with unlimited bounces.
Scene make_furnace(float albedo = 0.5f, float emission = 1.0f);
// Five GGX spheres of roughness 0.05…0.8 over a diffuse floor, two area lights.
Scene make_glossy_spheres();
// Thin pillars close to the viewer in front of a textured back wall: strong
// left/right-eye disocclusion.
Scene make_stereo_occluders();

// Tessellated UV sphere appended to `scene` (outward normals unless `inward`).
void add_sphere(Scene& scene, glm::vec3 centre, float radius, std::uint32_t material, int rings,
                int segments, bool inward = false);
// Axis-aligned box as 12 triangles with outward normals.
void add_box(Scene& scene, glm::vec3 lo, glm::vec3 hi, std::uint32_t material);

}  // namespace fovea::renderer
