#pragma once
// Typed binding structs of the reconstruction kernels: one named buffer per
// `layout(binding = ...)`, indices from shaders/include/fovea/shaders/recon_bindings.h (the
// constants the GLSL uses). A struct whose field count differs from the kernel's binding
// count fails to compile; a slot list that misses or repeats a binding fails at start-up
// (gpu::DescriptorSet::bind_all). Each binding's type is the shader's (kernel() in
// buffers.hpp): inputs read per cell are texel buffers, so their buffers carry a texel
// format (cells() in buffers.hpp), or binding them fails at start-up naming the binding.
#include <array>

#include "fovea/gpu/descriptors.hpp"
#include "fovea/shaders/recon_bindings.h"

namespace fovea::reconstruct {

using Buf = const gpu::Buffer*;

#define FOVEA_BINDING_COUNT(count)           \
  static constexpr std::uint32_t kCount = count; \
  using Slots = std::array<gpu::BufferSlot, kCount>;

struct AccumulateBindings {
  FOVEA_BINDING_COUNT(RECON_ACC_COUNT)
  Buf maps, tables, samples, direct, indirect, normal_depth, position_material, prev_direct, prev_indirect, prev_pos,
      prev_nrm, out_direct, out_indirect, out_pos, out_nrm, tap_idx, tap_w, materials, prev_restart, out_restart, luts,
      albedo, prev_albedo, out_albedo, live;
  Slots slots() const {
    return {{{RECON_MAPS, maps},
             {RECON_TABLES, tables},
             {RECON_ACC_SAMPLES, samples},
             {RECON_ACC_DIRECT, direct},
             {RECON_ACC_INDIRECT, indirect},
             {RECON_ACC_NORMAL_DEPTH, normal_depth},
             {RECON_ACC_POSITION_MATERIAL, position_material},
             {RECON_ACC_PREV_DIRECT, prev_direct},
             {RECON_ACC_PREV_INDIRECT, prev_indirect},
             {RECON_ACC_PREV_POS, prev_pos},
             {RECON_ACC_PREV_NRM, prev_nrm},
             {RECON_ACC_OUT_DIRECT, out_direct},
             {RECON_ACC_OUT_INDIRECT, out_indirect},
             {RECON_ACC_OUT_POS, out_pos},
             {RECON_ACC_OUT_NRM, out_nrm},
             {RECON_ACC_TAP_IDX, tap_idx},
             {RECON_ACC_TAP_W, tap_w},
             {RECON_ACC_MATERIALS, materials},
             {RECON_ACC_PREV_RESTART, prev_restart},
             {RECON_ACC_OUT_RESTART, out_restart},
             {RECON_ACC_LUTS, luts},
             {RECON_ACC_ALBEDO, albedo},
             {RECON_ACC_PREV_ALBEDO, prev_albedo},
             {RECON_ACC_OUT_ALBEDO, out_albedo},
             {RECON_ACC_LIVE, live}}};
  }
};

struct ShareBindings {
  FOVEA_BINDING_COUNT(RECON_SHARE_COUNT)
  Buf maps, tables, pos, nrm, acc_direct, acc_indirect, other_pos, other_nrm, other_indirect, shared, z, edge, luts,
      live;
  Slots slots() const {
    return {{{RECON_MAPS, maps},
             {RECON_TABLES, tables},
             {RECON_SHARE_POS, pos},
             {RECON_SHARE_NRM, nrm},
             {RECON_SHARE_ACC_DIRECT, acc_direct},
             {RECON_SHARE_ACC_INDIRECT, acc_indirect},
             {RECON_SHARE_OTHER_POS, other_pos},
             {RECON_SHARE_OTHER_NRM, other_nrm},
             {RECON_SHARE_OTHER_INDIRECT, other_indirect},
             {RECON_SHARE_SHARED, shared},
             {RECON_SHARE_Z, z},
             {RECON_SHARE_EDGE, edge},
             {RECON_SHARE_LUTS, luts},
             {RECON_SHARE_LIVE, live}}};
  }
};

struct BmfrBindings {
  FOVEA_BINDING_COUNT(RECON_BMFR_COUNT)
  Buf pos, nrm, z, fitted, columns, materials, excess, edge;
  Slots slots() const {
    return {{{RECON_BMFR_POS, pos},
             {RECON_BMFR_NRM, nrm},
             {RECON_BMFR_Z, z},
             {RECON_BMFR_FITTED, fitted},
             {RECON_BMFR_COLUMNS, columns},
             {RECON_BMFR_MATERIALS, materials},
             {RECON_BMFR_EXCESS, excess},
             {RECON_BMFR_EDGE, edge}}};
  }
};

struct PostBindings {
  FOVEA_BINDING_COUNT(RECON_POST_COUNT)
  Buf pos, tap_idx, tap_w, source, acc_direct, prev, out, prev_acc_direct, excess, sum, live, frame_direct;
  Slots slots() const {
    return {{{RECON_POST_POS, pos},
             {RECON_POST_TAP_IDX, tap_idx},
             {RECON_POST_TAP_W, tap_w},
             {RECON_POST_SOURCE, source},
             {RECON_POST_ACC_DIRECT, acc_direct},
             {RECON_POST_PREV, prev},
             {RECON_POST_OUT, out},
             {RECON_POST_PREV_ACC_DIRECT, prev_acc_direct},
             {RECON_POST_EXCESS, excess},
             {RECON_POST_SUM, sum},
             {RECON_POST_LIVE, live},
             {RECON_POST_FRAME_DIRECT, frame_direct}}};
  }
};

struct TaaBindings {
  FOVEA_BINDING_COUNT(RECON_TAA_COUNT)
  Buf maps, tables, pos, tap_idx, tap_w, post, albedo, prev_final, final_color, nrm, restart, live, prev_final_albedo,
      final_albedo;
  Slots slots() const {
    return {{{RECON_MAPS, maps},
             {RECON_TABLES, tables},
             {RECON_TAA_POS, pos},
             {RECON_TAA_TAP_IDX, tap_idx},
             {RECON_TAA_TAP_W, tap_w},
             {RECON_TAA_POST, post},
             {RECON_TAA_ALBEDO, albedo},
             {RECON_TAA_PREV_FINAL, prev_final},
             {RECON_TAA_FINAL, final_color},
             {RECON_TAA_NRM, nrm},
             {RECON_TAA_RESTART, restart},
             {RECON_TAA_LIVE, live},
             {RECON_TAA_PREV_FINAL_ALBEDO, prev_final_albedo},
             {RECON_TAA_FINAL_ALBEDO, final_albedo}}};
  }
};

struct MipBindings {
  FOVEA_BINDING_COUNT(RECON_MIP_COUNT)
  Buf maps, tables, mips;
  Slots slots() const { return {{{RECON_MAPS, maps}, {RECON_TABLES, tables}, {RECON_MIP_MIPS, mips}}}; }
};

struct ResolveBindings {
  FOVEA_BINDING_COUNT(RECON_RESOLVE_COUNT)
  Buf maps, tables, mips, offsets, screen, pos, depth, luts, albedo, primary;
  Slots slots() const {
    return {{{RECON_MAPS, maps},
             {RECON_TABLES, tables},
             {RECON_RESOLVE_MIPS, mips},
             {RECON_RESOLVE_OFFSETS, offsets},
             {RECON_RESOLVE_SCREEN, screen},
             {RECON_RESOLVE_POS, pos},
             {RECON_RESOLVE_DEPTH, depth},
             {RECON_RESOLVE_LUTS, luts},
             {RECON_RESOLVE_ALBEDO, albedo},
             {RECON_RESOLVE_PRIMARY, primary}}};
  }
};

struct BlurBindings {
  FOVEA_BINDING_COUNT(RECON_BLUR_COUNT)
  Buf maps, tables, src, dst;
  Slots slots() const {
    return {{{RECON_MAPS, maps}, {RECON_TABLES, tables}, {RECON_BLUR_SRC, src}, {RECON_BLUR_DST, dst}}};
  }
};

struct TemporalBindings {
  FOVEA_BINDING_COUNT(RECON_TEMPORAL_COUNT)
  Buf screen, prev, sums;
  Slots slots() const {
    return {{{RECON_TEMPORAL_SCREEN, screen}, {RECON_TEMPORAL_PREV, prev}, {RECON_TEMPORAL_SUMS, sums}}};
  }
};

#undef FOVEA_BINDING_COUNT

// One pointer field per binding: a field added or dropped without the constant breaks here.
static_assert(sizeof(AccumulateBindings) == AccumulateBindings::kCount * sizeof(Buf));
static_assert(sizeof(ShareBindings) == ShareBindings::kCount * sizeof(Buf));
static_assert(sizeof(BmfrBindings) == BmfrBindings::kCount * sizeof(Buf));
static_assert(sizeof(PostBindings) == PostBindings::kCount * sizeof(Buf));
static_assert(sizeof(TaaBindings) == TaaBindings::kCount * sizeof(Buf));
static_assert(sizeof(MipBindings) == MipBindings::kCount * sizeof(Buf));
static_assert(sizeof(ResolveBindings) == ResolveBindings::kCount * sizeof(Buf));
static_assert(sizeof(BlurBindings) == BlurBindings::kCount * sizeof(Buf));
static_assert(sizeof(TemporalBindings) == TemporalBindings::kCount * sizeof(Buf));

}  // namespace fovea::reconstruct
