// Descriptor binding indices of the reconstruction kernels (shaders/recon_*.comp), one
// definition for the GLSL `layout(binding = ...)` and the C++ binding structs
// (reconstruct/src/bindings.hpp). gpu::ComputePipeline checks the layout against the
// SPIR-V at start-up, DescriptorSet::bind_all that every binding is given once. Per-cell
// inputs are declared `textureBuffer` / `utextureBuffer` and read with texelFetch: on
// lavapipe a storage-buffer load whose address differs per invocation is a loop over the
// SIMD lanes, a texel fetch one vector gather (docs/gpu.md, "Texel buffers").
#ifndef FOVEA_SHADERS_RECON_BINDINGS_H
#define FOVEA_SHADERS_RECON_BINDINGS_H

// The grid mappings (ReconGrid[3]: this frame, previous frame, other eye) and their column
// tables: the same two bindings in every kernel that maps between grid and display. Kernels
// that map display positions to grid coordinates also bind the mappings' radius lookup
// tables (their *_LUTS binding; recon_map.h, RG_RADIUS_LUT).
#define RECON_MAPS 0
#define RECON_TABLES 1

// recon_accumulate.comp (BMFR Phase I)
#define RECON_ACC_SAMPLES 2
#define RECON_ACC_DIRECT 3
#define RECON_ACC_INDIRECT 4
#define RECON_ACC_NORMAL_DEPTH 5
#define RECON_ACC_POSITION_MATERIAL 6
#define RECON_ACC_PREV_DIRECT 7
#define RECON_ACC_PREV_INDIRECT 8
#define RECON_ACC_PREV_POS 9
#define RECON_ACC_PREV_NRM 10
#define RECON_ACC_OUT_DIRECT 11
#define RECON_ACC_OUT_INDIRECT 12
#define RECON_ACC_OUT_POS 13
#define RECON_ACC_OUT_NRM 14
#define RECON_ACC_TAP_IDX 15
#define RECON_ACC_TAP_W 16
#define RECON_ACC_MATERIALS 17
#define RECON_ACC_PREV_RESTART 18
#define RECON_ACC_OUT_RESTART 19
#define RECON_ACC_LUTS 20
#define RECON_ACC_ALBEDO 21
#define RECON_ACC_PREV_ALBEDO 22
#define RECON_ACC_OUT_ALBEDO 23
#define RECON_ACC_LIVE 24
#define RECON_ACC_COUNT 25

// recon_share.comp (stereo gather of indirect diffuse)
#define RECON_SHARE_POS 2
#define RECON_SHARE_NRM 3
#define RECON_SHARE_ACC_DIRECT 4
#define RECON_SHARE_ACC_INDIRECT 5
#define RECON_SHARE_OTHER_POS 6
#define RECON_SHARE_OTHER_NRM 7
#define RECON_SHARE_OTHER_INDIRECT 8
#define RECON_SHARE_SHARED 9
#define RECON_SHARE_Z 10
#define RECON_SHARE_EDGE 11
#define RECON_SHARE_LUTS 12
#define RECON_SHARE_LIVE 13
#define RECON_SHARE_COUNT 14

// recon_bmfr_fit.comp (BMFR Phase II)
#define RECON_BMFR_POS 0
#define RECON_BMFR_NRM 1
#define RECON_BMFR_Z 2
#define RECON_BMFR_FITTED 3
#define RECON_BMFR_COLUMNS 4
#define RECON_BMFR_MATERIALS 5
#define RECON_BMFR_EXCESS 6
#define RECON_BMFR_EDGE 7
#define RECON_BMFR_COUNT 8

// recon_post.comp (BMFR Phase III)
#define RECON_POST_POS 0
#define RECON_POST_TAP_IDX 1
#define RECON_POST_TAP_W 2
#define RECON_POST_SOURCE 3
#define RECON_POST_ACC_DIRECT 4
#define RECON_POST_PREV 5
#define RECON_POST_OUT 6
#define RECON_POST_PREV_ACC_DIRECT 7
#define RECON_POST_EXCESS 8
#define RECON_POST_SUM 9
#define RECON_POST_LIVE 10
#define RECON_POST_FRAME_DIRECT 11  // the tracer's direct light this frame: .w its samples
#define RECON_POST_COUNT 12

// recon_taa.comp
#define RECON_TAA_POS 2
#define RECON_TAA_TAP_IDX 3
#define RECON_TAA_TAP_W 4
#define RECON_TAA_POST 5
#define RECON_TAA_ALBEDO 6
#define RECON_TAA_PREV_FINAL 7
#define RECON_TAA_FINAL 8
#define RECON_TAA_NRM 9
#define RECON_TAA_RESTART 10
#define RECON_TAA_LIVE 11
#define RECON_TAA_PREV_FINAL_ALBEDO 12  // the albedo in the previous frame's output (below)
#define RECON_TAA_FINAL_ALBEDO 13       // the albedo in this frame's output, blended as the colour
#define RECON_TAA_COUNT 14

// recon_mip.comp
#define RECON_MIP_MIPS 2
#define RECON_MIP_COUNT 3

// recon_resolve.comp (the display image and the display-space depth)
#define RECON_RESOLVE_MIPS 2
#define RECON_RESOLVE_OFFSETS 3
#define RECON_RESOLVE_SCREEN 4
#define RECON_RESOLVE_POS 5
#define RECON_RESOLVE_DEPTH 6
#define RECON_RESOLVE_LUTS 7
#define RECON_RESOLVE_ALBEDO 8   // the albedo in the cells' output (TAA's RECON_TAA_FINAL_ALBEDO)
#define RECON_RESOLVE_PRIMARY 9  // the display pixels' first hits near the gaze (pt_primary.h)
#define RECON_RESOLVE_COUNT 10

// recon_blur.comp
#define RECON_BLUR_SRC 2
#define RECON_BLUR_DST 3
#define RECON_BLUR_COUNT 4

// recon_temporal.comp (the temporal error of the display image, on the device)
#define RECON_TEMPORAL_SCREEN 0
#define RECON_TEMPORAL_PREV 1
#define RECON_TEMPORAL_SUMS 2
#define RECON_TEMPORAL_COUNT 3

#endif
