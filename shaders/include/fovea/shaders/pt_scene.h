// Scene data of the path tracer on the GPU (shared C++/GLSL, std430 = C++ layout).
#ifndef FOVEA_SHADERS_PT_SCENE_H
#define FOVEA_SHADERS_PT_SCENE_H
#include "fovea/shaders/common.h"

#ifdef __cplusplus
#include <cstddef>
namespace fovea::shaders {
#endif

// Depth bound of the binary tree the builder makes before collapsing it to 4-wide nodes:
// SAH splits stop at depth 60, and larger leaves are then halved until they fit
// kPtBvhMaxLeaf (at most 20 more levels for the 4·10⁶-triangle scene limit).
FOVEA_CONST FOVEA_UINT kPtBvhMaxDepth = 80;
FOVEA_CONST FOVEA_UINT kPtBvhMaxLeaf = 255;
// Traversal stack: at most 3 deferred children per 4-wide level, and a 4-wide tree is
// never deeper than the binary one.
FOVEA_CONST FOVEA_UINT kPtBvhStackSize = 3 * kPtBvhMaxDepth;
// Specialization constants (constant_id) of the shaders that traverse: the stack entries a
// scene needs, 3 × its 4-wide depth (a smaller stack is cheaper on lavapipe), and the
// device's maxComputeSharedMemorySize (the stack goes to shared memory when it fits).
FOVEA_CONST FOVEA_UINT kPtSpecBvhStack = 16;
FOVEA_CONST FOVEA_UINT kPtSpecSharedBytes = 17;
FOVEA_CONST FOVEA_UINT kPtNoHit = 0xFFFFFFFF;

// Compressed 4-wide BVH node, 64 bytes (Ylitie, Karras, Laine 2017, "Efficient incoherent
// ray traversal on GPUs through compressed wide BVHs", §3.1): the four child boxes are
// quantised to 8 bits per plane on a grid of origin + 2^e·q per axis, rounded outwards,
// so one small fetch serves four box tests. Byte k of lo_*, hi_*, counts is slot k.
// counts byte k > 0: slot k is a leaf of triangles [child[k], child[k] + count) of the
// reordered triangles; 0: an inner node at index child[k]; child[k] == kPtNoHit: empty.
struct PtBvhNode {
  float origin_x, origin_y, origin_z;
  FOVEA_UINT exponents;  // e per axis, signed bytes 0..2
  FOVEA_UINT lo_x, lo_y, lo_z;
  FOVEA_UINT hi_x, hi_y, hi_z;
  FOVEA_UINT child[4];
  FOVEA_UINT counts;
  FOVEA_UINT pad;
};

// Triangle vertices in BVH order, what traversal reads (48 bytes).
struct PtTriangle {
  float v0_x, v0_y, v0_z;
  FOVEA_UINT material;
  float v1_x, v1_y, v1_z;
  FOVEA_UINT source;  // index of the triangle in the scene (for debugging and tests)
  float v2_x, v2_y, v2_z;
  float light_pdf;  // emissive: P(choose this triangle) / area, for MIS; else 0
};

// Shading attributes of a triangle, same order (64 bytes).
struct PtShading {
  float n0_x, n0_y, n0_z;
  float n1_x, n1_y, n1_z;
  float n2_x, n2_y, n2_z;
  float uv0_x, uv0_y, uv1_x, uv1_y, uv2_x, uv2_y;
  float pad;
};

struct PtMaterial {
  float base_r, base_g, base_b;
  FOVEA_INT texture;  // index into the texture table, -1 for none
  float emit_r, emit_g, emit_b;
  float metallic;
  float roughness, specular;
  FOVEA_UINT double_sided;  // 1: back faces shade and emit with the normal reversed; 0: black
  float pad;
};

// A texture in the shared texel buffer (RGBA8 sRGB words): `levels` mip levels from
// `offset`, level l of max(width >> l, 1) × max(height >> l, 1) texels after level l − 1.
struct PtTextureInfo {
  FOVEA_UINT offset, width, height, levels;
};

// Emissive triangle for next-event estimation, chosen by power with a CDF.
struct PtLight {
  FOVEA_UINT triangle;  // index into the BVH-ordered triangles
  float cdf;            // inclusive prefix sum of the selection probabilities
  float pmf;
  float area;
};

// Directional albedo of the GGX specular lobe (pt_bsdf_eval's f_spec with Schlick Fresnel,
// which is linear in F0): E(μ, α, F0) = F0·A + B, and its cosine-weighted hemispherical
// mean E_avg = 2∫E(μ)μ dμ = F0·A_avg + B_avg. A table of vec4 (A, B, A_avg, B_avg) with
// kPtGgxTableSize² entries, index = r_index · size + μ_index, nodes √μ = i/(size−1) and
// √α = j/(size−1), bilinear in (√μ, √α); built by renderer/src/ggx_albedo.cpp.
FOVEA_CONST FOVEA_UINT kPtGgxTableSize = 32;

#ifdef __cplusplus
static_assert(sizeof(PtBvhNode) == 64 && sizeof(PtTriangle) == 48 && sizeof(PtShading) == 64);
// pt_node() and pt_tri() (pt_traverse.h) decode these words from uvec4 loads.
static_assert(offsetof(PtBvhNode, lo_x) == 16 && offsetof(PtBvhNode, child) == 40 && offsetof(PtBvhNode, counts) == 56);
static_assert(offsetof(PtTriangle, source) == 28 && offsetof(PtTriangle, light_pdf) == 44);
static_assert(sizeof(PtMaterial) == 48 && sizeof(PtTextureInfo) == 16 && sizeof(PtLight) == 16);
}  // namespace fovea::shaders
#endif
#endif
