#include "fovea/compositor/frame_pipeline.hpp"

#include <algorithm>
#include <cstring>
#include <initializer_list>

#include "fovea/compositor/bmfr.hpp"
#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "fovea/gpu/buffer.hpp"
#include "fovea/gpu/descriptors.hpp"
#include "fovea/gpu/grid_pass.hpp"
#include "fovea/gpu/pipeline.hpp"
#include "fovea/gpu/timer.hpp"

namespace fovea::compositor {

namespace {

using shaders::GridColumn;
using shaders::ReconGrid;

constexpr std::uint32_t kMaxMipLevels = 12;

gpu::ComputePipeline make_pipeline(gpu::Context& ctx, const char* shader, std::size_t bindings, std::uint32_t push) {
  return gpu::ComputePipeline(
      ctx, {.shader = shader, .sets = {std::vector<gpu::Binding>(bindings, gpu::Binding::StorageBuffer)},
            .push_constant_bytes = push});
}

gpu::DescriptorSet make_set(gpu::Context& ctx, const gpu::ComputePipeline& p,
                            std::initializer_list<const gpu::Buffer*> buffers) {
  gpu::DescriptorSet set(ctx, p.set_layout(0));
  std::uint32_t b = 0;
  for (const gpu::Buffer* buf : buffers) set.bind(b++, *buf);
  return set;
}

gpu::Buffer storage(gpu::Context& ctx, VkDeviceSize bytes, const char* name,
                    gpu::Memory memory = gpu::Memory::DeviceLocal) {
  return gpu::Buffer(ctx, {.size = std::max<VkDeviceSize>(bytes, 16), .usage = gpu::BufferUsage::Storage,
                           .memory = memory, .name = name});
}

struct Kernels {
  gpu::ComputePipeline accumulate, share, post, taa, mip, resolve, blur, depth;
  BmfrFit fit;
  Kernels(gpu::Context& ctx, BmfrPrecision precision)
      : accumulate(make_pipeline(ctx, "recon_accumulate.comp.spv", 18, sizeof(shaders::ReconAccumulatePush))),
        share(make_pipeline(ctx, "recon_share.comp.spv", 11, sizeof(shaders::ReconSharePush))),
        post(make_pipeline(ctx, "recon_post.comp.spv", 7, sizeof(shaders::ReconPostPush))),
        taa(make_pipeline(ctx, "recon_taa.comp.spv", 9, sizeof(shaders::ReconPostPush))),
        mip(make_pipeline(ctx, "recon_mip.comp.spv", 3, sizeof(shaders::ReconMipPush))),
        resolve(make_pipeline(ctx, "recon_resolve.comp.spv", 5, sizeof(shaders::ReconResolvePush))),
        blur(make_pipeline(ctx, "recon_blur.comp.spv", 4, sizeof(shaders::ReconBlurPush))),
        depth(make_pipeline(ctx, "recon_depth.comp.spv", 4, sizeof(shaders::ReconResolvePush))),
        fit(ctx, {.precision = precision}) {}
};

}  // namespace

struct EyeState {
  core::Eye eye = core::Eye::Left;
  std::unique_ptr<core::SampleDistribution> dist;
  core::View base_view;
  core::Pose pose;
  std::unique_ptr<gpu::GridPass> grid_pass;
  gpu::Buffer grid;
  renderer::TraceOutputs trace;
  std::uint32_t cells = 0, pcols = 0, prows = 0, columns = 0, table_len = 0, other_table_len = 0;
  gpu::Buffer maps, tables;
  ReconGrid prev{};
  std::vector<GridColumn> prev_table;
  gpu::Buffer acc_d[2], acc_i[2], vpos[2], vnrm[2], post[2], final_[2];
  gpu::Buffer tap_idx, tap_w, shared, z, fitted;
  std::uint32_t levels = 1;
  std::vector<std::uint32_t> level_rows, level_offset;
  gpu::Buffer mips, offsets, screen_a, screen_b, depth;
  gpu::DescriptorSet acc_set[2], share_set[2], fit_set[2], post_set[2], taa_set[2], depth_set[2];
  gpu::DescriptorSet mip_set, resolve_set, blur_h, blur_v;

  std::vector<GridColumn> table() const {
    std::vector<GridColumn> t = dist->column_table();
    t.resize(table_len, GridColumn{});
    return t;
  }
};

struct FramePipeline::Impl {
  gpu::Context& ctx;
  ReconSettings settings;
  renderer::PathConfig path;
  Kernels k;
  renderer::PathTracer tracer;
  std::vector<std::unique_ptr<EyeState>> eyes;
  gpu::GpuTimer timer;
  std::uint32_t frames_done = 0;  // frames since the last reset
  int parity = 0;                 // history buffers written by the last frame

  Impl(gpu::Context& c, const renderer::GpuScene& scene, const renderer::PathConfig& p, const ReconSettings& s)
      : ctx(c), settings(s), path(p), k(c, s.bmfr_precision), tracer(c, scene), timer(c) {}

  void write_maps(EyeState& e, const EyeState* other) {
    ReconGrid m[3] = {recon_grid(*e.dist, e.pose, 0), e.prev, ReconGrid{}};
    m[1].table_offset = e.table_len;
    if (other) m[2] = recon_grid(*other->dist, other->pose, 2 * e.table_len);
    std::memcpy(e.maps.mapped().data(), m, sizeof(m));
    std::vector<GridColumn> t = e.table();
    std::vector<GridColumn> prev = e.prev_table;
    prev.resize(e.table_len, GridColumn{});
    t.insert(t.end(), prev.begin(), prev.end());
    if (other) {
      std::vector<GridColumn> o = other->table();
      o.resize(e.other_table_len, GridColumn{});
      t.insert(t.end(), o.begin(), o.end());
    }
    std::memcpy(e.tables.mapped().data(), t.data(), t.size() * sizeof(GridColumn));
  }

  void build_eye(EyeState& e, const core::DisplayPreset& display, const core::DistributionParams& dp) {
    e.base_view = display.view(e.eye);
    e.dist = core::make_distribution(e.base_view, dp);
    if (!e.dist->invertible())
      throw core::InputError(std::string("--distribution: ") + core::distribution_name(dp.kind) +
                             " has no screen-to-grid mapping; the reconstruction needs one");
    e.grid_pass = std::make_unique<gpu::GridPass>(ctx);
    e.pcols = std::uint32_t(e.dist->padded_columns());
    e.prows = std::uint32_t(e.dist->padded_rows());
    e.columns = std::uint32_t(e.dist->columns());
    e.cells = e.pcols * e.prows;
    e.table_len = std::max<std::uint32_t>(1, std::uint32_t(e.dist->column_table().size()));
    e.grid = storage(ctx, gpu::GridPass::samples_bytes(*e.dist), "recon.grid");
    e.trace = tracer.bind(e.grid, e.cells);
    const VkDeviceSize v4 = VkDeviceSize(e.cells) * 16;
    e.maps = storage(ctx, 3 * sizeof(ReconGrid), "recon.maps", gpu::Memory::HostVisible);
    for (int p = 0; p < 2; ++p) {
      e.acc_d[p] = storage(ctx, v4, "recon.acc_direct");
      e.acc_i[p] = storage(ctx, v4, "recon.acc_indirect");
      e.vpos[p] = storage(ctx, v4, "recon.vpos");
      e.vnrm[p] = storage(ctx, v4, "recon.vnrm");
      e.post[p] = storage(ctx, v4, "recon.post");
      e.final_[p] = storage(ctx, v4, "recon.final");
    }
    e.tap_idx = storage(ctx, v4, "recon.tap_idx");
    e.tap_w = storage(ctx, v4, "recon.tap_w");
    e.shared = storage(ctx, v4, "recon.shared_indirect");
    e.z = storage(ctx, v4, "recon.z");
    e.fitted = storage(ctx, v4, "recon.fitted");
    // φ-only mip chain (polar grids): level l has ceil(rows / 2^l) rows.
    const bool polar = e.dist->gpu_params().family != shaders::kFamilyCartesian;
    std::uint32_t rows = e.prows, offset = 0;
    e.level_rows.clear();
    e.level_offset.clear();
    do {
      e.level_rows.push_back(rows);
      e.level_offset.push_back(offset);
      offset += rows * e.pcols;
      rows = (rows + 1) / 2;
    } while (polar && e.level_rows.back() > 1 && e.level_rows.size() < kMaxMipLevels);
    e.levels = std::uint32_t(e.level_rows.size());
    e.mips = storage(ctx, VkDeviceSize(offset) * 16, "recon.mips");
    e.offsets = storage(ctx, e.level_offset.size() * 4, "recon.mip_offsets");
    e.offsets.upload(e.level_offset);
    const VkDeviceSize screen = VkDeviceSize(e.base_view.width()) * e.base_view.height() * 16;
    e.screen_a = storage(ctx, screen, "recon.screen");
    e.screen_b = storage(ctx, screen, "recon.screen_tmp");
    e.depth = storage(ctx, screen / 4, "recon.depth");
  }

  void bind_eye(EyeState& e, const EyeState& o) {
    e.other_table_len = o.table_len;
    e.tables = storage(ctx, VkDeviceSize(2 * e.table_len + o.table_len) * sizeof(GridColumn), "recon.tables",
                       gpu::Memory::HostVisible);
    const renderer::TraceOutputs& t = e.trace;
    for (int p = 0; p < 2; ++p) {
      const int q = 1 - p;  // history read by a frame writing p
      e.acc_set[p] = make_set(ctx, k.accumulate,
                              {&e.maps, &e.tables, &e.grid, &t.direct(), &t.indirect(), &t.normal_depth(),
                               &t.position_material(), &e.acc_d[q], &e.acc_i[q], &e.vpos[q], &e.vnrm[q], &e.acc_d[p],
                               &e.acc_i[p], &e.vpos[p], &e.vnrm[p], &e.tap_idx, &e.tap_w, &tracer.scene().materials()});
      e.share_set[p] = make_set(ctx, k.share,
                                {&e.maps, &e.tables, &e.vpos[p], &e.vnrm[p], &e.acc_d[p], &e.acc_i[p], &o.vpos[p],
                                 &o.vnrm[p], &o.acc_i[p], &e.shared, &e.z});
      e.fit_set[p] = k.fit.bind(e.vpos[p], e.vnrm[p], e.z, e.fitted);
      const gpu::Buffer* source = settings.denoiser == Denoiser::Bmfr ? &e.fitted : &e.z;
      e.post_set[p] = make_set(ctx, k.post, {&e.vpos[p], &e.tap_idx, &e.tap_w, source, &e.acc_d[p], &e.post[q], &e.post[p]});
      e.taa_set[p] = make_set(ctx, k.taa, {&e.maps, &e.tables, &e.vpos[p], &e.tap_idx, &e.tap_w, &e.post[p],
                                            &t.albedo(), &e.final_[q], &e.final_[p]});
      e.depth_set[p] = make_set(ctx, k.depth, {&e.maps, &e.tables, &e.vpos[p], &e.depth});
    }
    e.mip_set = make_set(ctx, k.mip, {&e.maps, &e.tables, &e.mips});
    e.resolve_set = make_set(ctx, k.resolve, {&e.maps, &e.tables, &e.mips, &e.offsets, &e.screen_a});
    e.blur_h = make_set(ctx, k.blur, {&e.maps, &e.tables, &e.screen_a, &e.screen_b});
    e.blur_v = make_set(ctx, k.blur, {&e.maps, &e.tables, &e.screen_b, &e.screen_a});
  }

  EyeState* other(const EyeState& e) const {
    if (eyes.size() < 2) return nullptr;
    return eyes[0].get() == &e ? eyes[1].get() : eyes[0].get();
  }

  // Mips from the grid image already in level 0, resolve, blur: into screen_a.
  void record_resolve(VkCommandBuffer cmd, bool blur) {
    for (std::uint32_t l = 0; l + 1 < max_levels(); ++l) {
      for (auto& e : eyes) {
        if (l + 1 >= e->levels) continue;
        const shaders::ReconMipPush push{e->pcols, e->level_rows[l], e->level_rows[l + 1], l, e->level_offset[l],
                                         e->level_offset[l + 1], 0, 0};
        k.mip.run(cmd, {&e->mip_set}, push, e->pcols, e->level_rows[l + 1]);
      }
      gpu::compute_to_compute(cmd);
    }
    for (auto& e : eyes) {
      const auto w = std::uint32_t(e->base_view.width()), h = std::uint32_t(e->base_view.height());
      k.resolve.run(cmd, {&e->resolve_set}, shaders::ReconResolvePush{w, h, e->levels, 0}, w, h);
    }
    gpu::compute_to_compute(cmd);
    if (!blur) return;
    for (int pass = 0; pass < 2; ++pass) {
      for (auto& e : eyes) {
        const auto w = std::uint32_t(e->base_view.width()), h = std::uint32_t(e->base_view.height());
        const shaders::ReconBlurPush push{w, h, std::uint32_t(pass), 0, float(settings.blur_fovea_deg),
                                          float(settings.blur_sigma_deg_at_30 / (30.0 - settings.blur_fovea_deg)),
                                          float(settings.blur_max_sigma_px), 0};
        k.blur.run(cmd, {pass == 0 ? &e->blur_h : &e->blur_v}, push, w, h);
      }
      gpu::compute_to_compute(cmd);
    }
  }

  // Every device buffer written per frame, set to `word`. Vulkan leaves new memory undefined
  // (lavapipe hands out recycled heap memory), and a buffer that a configuration never writes
  // (BMFR's output without BMFR) would otherwise read back differently from run to run.
  void fill(std::uint32_t word) {
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      for (auto& e : eyes) {
        const renderer::TraceOutputs& t = e->trace;
        for (const gpu::Buffer* b : {static_cast<const gpu::Buffer*>(&e->grid), &t.direct(), &t.indirect(), &t.albedo(), &t.normal_depth(),
                                     &t.position_material(), &t.radiance()})
          gpu::fill_buffer(cmd, *b, word);
        for (const gpu::Buffer* b : {&e->tap_idx, &e->tap_w, &e->shared, &e->z, &e->fitted, &e->mips, &e->screen_a,
                                     &e->screen_b, &e->depth})
          gpu::fill_buffer(cmd, *b, word);
        for (int p = 0; p < 2; ++p)
          for (const gpu::Buffer* b : {&e->acc_d[p], &e->acc_i[p], &e->vpos[p], &e->vnrm[p], &e->post[p], &e->final_[p]})
            gpu::fill_buffer(cmd, *b, word);
      }
    });
  }

  std::uint32_t max_levels() const {
    std::uint32_t m = 1;
    for (const auto& e : eyes) m = std::max(m, e->levels);
    return m;
  }
};

FramePipeline::FramePipeline(gpu::Context& ctx, const renderer::GpuScene& scene, const core::DisplayPreset& display,
                             const core::DistributionParams& distribution, const ReconSettings& settings,
                             const renderer::PathConfig& path, bool mono)
    : impl_(std::make_unique<Impl>(ctx, scene, path, settings)) {
  if (mono && settings.share != StereoShare::Off)
    throw core::InputError("--stereo-share: sharing needs both eyes");
  for (int i = 0; i < (mono ? 1 : 2); ++i) {
    auto e = std::make_unique<EyeState>();
    e->eye = core::Eye(i);
    impl_->build_eye(*e, display, distribution);
    impl_->eyes.push_back(std::move(e));
  }
  for (auto& e : impl_->eyes) {
    const EyeState* o = impl_->other(*e);
    impl_->bind_eye(*e, o ? *o : *e);
  }
  impl_->fill(0);
}

FramePipeline::~FramePipeline() = default;

void FramePipeline::reset() { impl_->frames_done = 0; }

void FramePipeline::fill_buffers(std::uint32_t word) {
  impl_->fill(word);
  impl_->frames_done = 0;
}

FrameTimes FramePipeline::render(const std::array<core::Pose, 2>& eye_pose, const std::array<glm::dvec3, 2>& gaze,
                                 std::uint32_t frame) {
  Impl& m = *impl_;
  const int p = m.frames_done == 0 ? 0 : 1 - m.parity;
  const std::uint32_t has_history = m.frames_done > 0 ? 1u : 0u;
  for (auto& e : m.eyes) {
    const int i = int(e->eye);
    e->pose = eye_pose[i];
    e->dist->set_frame(gaze[i], frame);
    e->grid_pass->prepare(*e->dist);
  }
  for (auto& e : m.eyes) m.write_maps(*e, m.other(*e));
  const bool stereo = m.eyes.size() == 2;
  const bool alternate = stereo && m.settings.share == StereoShare::Alternate;
  const bool bmfr = m.settings.denoiser == Denoiser::Bmfr;

  m.ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    m.timer.begin(cmd);
    for (auto& e : m.eyes) e->grid_pass->record(cmd, e->grid);
    gpu::compute_to_compute(cmd);
    for (auto& e : m.eyes) {
      renderer::PathConfig cfg = m.path;
      // Alternating sharing: only one eye traces indirect diffuse this frame.
      if (alternate && int(e->eye) != int(frame % 2)) cfg.max_bounces = 0;
      m.tracer.record(cmd, e->trace, core::View(e->base_view.fov(), e->base_view.width(), e->base_view.height(), e->pose),
                      e->eye, frame, cfg);
    }
    gpu::compute_to_compute(cmd);
    m.timer.stage(cmd, "trace");
    for (auto& e : m.eyes) {
      const std::uint32_t fresh = alternate && int(e->eye) != int(frame % 2) ? 0u : 1u;
      m.k.accumulate.run(cmd, {&e->acc_set[p]}, shaders::ReconAccumulatePush{e->cells, has_history, fresh, 0,
                                                                            m.settings.alpha_min, 0, 0, 0},
                         e->cells);
    }
    gpu::compute_to_compute(cmd);
    for (auto& e : m.eyes) {
      const std::uint32_t share = stereo && m.settings.share != StereoShare::Off ? 1u : 0u;
      m.k.share.run(cmd, {&e->share_set[p]}, shaders::ReconSharePush{e->cells, share, 0, 0}, e->cells);
    }
    gpu::compute_to_compute(cmd);
    m.timer.stage(cmd, "accumulate");
    if (bmfr) {
      for (auto& e : m.eyes) {
        const glm::ivec2 off = m.settings.block_offsets ? bmfr_block_offset(frame) : glm::ivec2(0);
        m.k.fit.record(cmd, e->fit_set[p], {e->pcols, e->prows}, frame, off, m.settings.noise);
      }
      gpu::compute_to_compute(cmd);
    }
    m.timer.stage(cmd, "bmfr_fit");
    const shaders::ReconPostPush post{0, has_history, bmfr ? 1u : 0u, 0, m.settings.post_alpha_min,
                                      m.settings.taa_alpha, 0, 0};
    for (auto& e : m.eyes) {
      shaders::ReconPostPush pp = post;
      pp.cells = e->cells;
      m.k.post.run(cmd, {&e->post_set[p]}, pp, e->cells);
    }
    gpu::compute_to_compute(cmd);
    for (auto& e : m.eyes) {
      shaders::ReconPostPush pp = post;
      pp.cells = e->cells;
      m.k.taa.run(cmd, {&e->taa_set[p]}, pp, e->cells);
    }
    gpu::compute_to_transfer(cmd);
    m.timer.stage(cmd, "post");
    for (auto& e : m.eyes) gpu::copy_buffer(cmd, e->final_[p], e->mips, VkDeviceSize(e->cells) * 16);
    gpu::transfer_to_compute(cmd);
    for (auto& e : m.eyes) {
      const auto w = std::uint32_t(e->base_view.width()), h = std::uint32_t(e->base_view.height());
      m.k.depth.run(cmd, {&e->depth_set[p]}, shaders::ReconResolvePush{w, h, 0, 0}, w, h);
    }
    m.record_resolve(cmd, m.settings.blur);
    m.timer.stage(cmd, "resolve");
  });

  for (auto& e : m.eyes) {
    e->prev = recon_grid(*e->dist, e->pose, 0);
    e->prev_table = e->dist->column_table();
  }
  m.parity = p;
  ++m.frames_done;

  FrameTimes t;
  if (const auto stages = m.timer.read()) {
    for (const gpu::StageTime& s : *stages) {
      const double ms = double(s.duration_ns()) * 1e-6;
      if (s.name == "trace") t.trace += ms;
      else if (s.name == "resolve") t.resolve += ms;
      else t.reconstruct += ms;
      if (s.name == "bmfr_fit") t.bmfr_fit = ms;
      t.total += ms;
    }
  }
  return t;
}

core::Image FramePipeline::resolve_grid(core::Eye eye, const std::vector<glm::vec4>& grid, bool blur) {
  Impl& m = *impl_;
  EyeState* target = nullptr;
  for (auto& e : m.eyes)
    if (e->eye == eye) target = e.get();
  if (!target) throw core::InputError("resolve_grid: eye not rendered");
  if (grid.size() != target->cells) throw core::InputError("resolve_grid: grid size differs from the padded grid");
  for (auto& e : m.eyes) m.write_maps(*e, m.other(*e));
  target->mips.upload(grid);
  m.ctx.submit_and_wait([&](VkCommandBuffer cmd) { m.record_resolve(cmd, blur); });
  return image(eye);
}

core::Image FramePipeline::image(core::Eye e) const {
  for (const auto& s : impl_->eyes)
    if (s->eye == e) {
      core::Image img(s->base_view.width(), s->base_view.height());
      img.pixels = s->screen_a.download<glm::vec4>();
      img.pixels.resize(std::size_t(img.width) * img.height);
      return img;
    }
  throw core::InputError("image: eye not rendered");
}

std::vector<float> FramePipeline::depth(core::Eye e) const {
  for (const auto& s : impl_->eyes)
    if (s->eye == e) {
      std::vector<float> d = s->depth.download<float>();
      d.resize(std::size_t(s->base_view.width()) * std::size_t(s->base_view.height()));
      return d;
    }
  throw core::InputError("depth: eye not rendered");
}

std::vector<glm::vec4> FramePipeline::grid_buffer(core::Eye eye, GridBuffer which) const {
  const int p = impl_->parity;
  for (const auto& e : impl_->eyes) {
    if (e->eye != eye) continue;
    const gpu::Buffer* b = nullptr;
    switch (which) {
      case GridBuffer::Radiance: b = &e->trace.radiance(); break;
      case GridBuffer::AccDirect: b = &e->acc_d[p]; break;
      case GridBuffer::AccIndirect: b = &e->acc_i[p]; break;
      case GridBuffer::SharedIndirect: b = &e->shared; break;
      case GridBuffer::Fitted: b = &e->fitted; break;
      case GridBuffer::Final: b = &e->final_[p]; break;
      case GridBuffer::Albedo: b = &e->trace.albedo(); break;
      case GridBuffer::Position: b = &e->vpos[p]; break;
    }
    std::vector<glm::vec4> v = b->download<glm::vec4>();
    v.resize(e->cells);
    return v;
  }
  throw core::InputError("grid_buffer: eye not rendered");
}

std::vector<shaders::GridSample> FramePipeline::grid_samples(core::Eye eye) const {
  for (const auto& e : impl_->eyes)
    if (e->eye == eye) {
      std::vector<shaders::GridSample> v = e->grid.download<shaders::GridSample>();
      v.resize(e->cells);
      return v;
    }
  throw core::InputError("grid_samples: eye not rendered");
}

std::int64_t FramePipeline::traced_cells(core::Eye eye) const {
  std::int64_t n = 0;
  for (const auto& s : grid_samples(eye)) n += s.flags == 0 ? 1 : 0;
  return n;
}

const core::SampleDistribution& FramePipeline::distribution(core::Eye eye) const {
  for (const auto& e : impl_->eyes)
    if (e->eye == eye) return *e->dist;
  throw core::InputError("distribution: eye not rendered");
}

core::View FramePipeline::view(core::Eye eye) const {
  for (const auto& e : impl_->eyes)
    if (e->eye == eye) return core::View(e->base_view.fov(), e->base_view.width(), e->base_view.height(), e->pose);
  throw core::InputError("view: eye not rendered");
}

int FramePipeline::eyes() const { return int(impl_->eyes.size()); }
const ReconSettings& FramePipeline::settings() const { return impl_->settings; }

}  // namespace fovea::compositor
