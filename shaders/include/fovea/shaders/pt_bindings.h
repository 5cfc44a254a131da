// Descriptor binding indices of the path tracer (pt_trace.comp) and the ray caster
// (pt_raycast.comp), one definition for the GLSL `layout(binding = ...)` and the C++ that binds
// them (renderer/src/path_tracer.cpp, raycaster.cpp); gpu::ComputePipeline checks each layout's
// types against the SPIR-V at start-up. Scene data read per ray or path vertex are texel
// buffers (pt_traverse.h says why), the rest storage buffers.
#ifndef FOVEA_SHADERS_PT_BINDINGS_H
#define FOVEA_SHADERS_PT_BINDINGS_H

// The scene's BVH, the same in both kernels (texel buffers).
#define PT_BINDING_NODES 0  // PtBvhNode: pt_node()
#define PT_BINDING_TRIS 1   // PtTriangle: pt_tri()

// pt_trace.comp, set 0
#define PT_BINDING_SHADING 2     // texel buffer, PtShading: 4 texels each
#define PT_BINDING_MATERIALS 3   // texel buffer, PtMaterial: 3 texels each
#define PT_BINDING_LIGHTS 4      // texel buffer, PtLight: 1 texel each
#define PT_BINDING_TEX_TABLE 5   // PtTextureInfo per texture
#define PT_BINDING_TEXELS 6      // texel buffer, RGBA8 per texel
#define PT_BINDING_GRID 7        // GridSample per cell
#define PT_BINDING_OUT_DIRECT 8  // the outputs per cell (pt_trace.h)
#define PT_BINDING_OUT_INDIRECT 9
#define PT_BINDING_OUT_ALBEDO 10
#define PT_BINDING_OUT_NORMAL_DEPTH 11
#define PT_BINDING_OUT_POSITION_MATERIAL 12
#define PT_BINDING_OUT_RADIANCE 13
#define PT_BINDING_GGX_ALBEDO 14  // texel buffer, read by pt_sampling.h
#define PT_BINDING_LIVE_LIST 15   // the grid pass's live tiles (live_cells.h)
#define PT_BINDING_COUNT 16
// pt_trace.comp with ray queries, set 1 (pt_rayquery.h): the scene's top level.
#define PT_BINDING_TLAS 0

// pt_raycast.comp, set 0 (after the BVH)
#define RAYCAST_BINDING_RAYS 2
#define RAYCAST_BINDING_HITS 3
#define RAYCAST_BINDING_COUNT 4

#endif
