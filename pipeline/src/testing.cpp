#include "fovea/pipeline/testing.hpp"

#include "fovea/core/clock.hpp"
#include "fovea/core/error.hpp"
#include "fovea/shaders/live_cells.h"
#include "frame_pipeline_impl.hpp"

namespace fovea::pipeline::testing {

namespace {
double process_cpu_ms() { return core::ns_to_ms(core::process_cpu_ns()); }
}  // namespace

std::vector<glm::vec4> grid_buffer(const FramePipeline& pipeline, core::Eye eye, GridBuffer which) {
  auto& m = Access::impl(pipeline);
  const int i = m.index(eye, "grid_buffer");
  const EyeState& e = *m.eyes[std::size_t(i)];
  const int p = m.parity;
  const gpu::Buffer* b = nullptr;
  switch (which) {
    case GridBuffer::Radiance: b = &e.trace.radiance(); break;
    case GridBuffer::AccDirect: b = &m.accumulation->direct(i, p); break;
    case GridBuffer::AccIndirect: b = &m.accumulation->indirect(i, p); break;
    case GridBuffer::SharedIndirect: b = &m.gather->shared(i); break;
    case GridBuffer::Fitted:
      if (!m.bmfr) throw core::InputError("grid_buffer: no BMFR stage (denoiser none)");
      b = &m.bmfr->fitted(i);
      break;
    case GridBuffer::Final: b = &m.post->final_color(i, p); break;
    case GridBuffer::Albedo: b = &e.trace.albedo(); break;
    case GridBuffer::AccAlbedo: b = &m.accumulation->albedo(i, p); break;
    case GridBuffer::Position: b = &m.accumulation->position(i, p); break;
    case GridBuffer::TapWeight: b = &m.accumulation->tap_weight(i); break;
  }
  std::vector<glm::vec4> v = b->download<glm::vec4>();
  v.resize(e.cells);
  return v;
}

void fill_buffers(FramePipeline& pipeline, std::uint32_t word) {
  auto& m = Access::impl(pipeline);
  m.fill(word);
  pipeline.reset();
}

renderer::TraceOrder trace_order(const FramePipeline& pipeline, core::Eye e) {
  const auto& m = Access::impl(pipeline);
  m.index(e, "trace_order");  // throws for an eye not rendered
  return m.trace_order();
}

std::vector<std::uint32_t> live_cells(const FramePipeline& pipeline, core::Eye e) {
  const auto& m = Access::impl(pipeline);
  const auto list = m.eyes[std::size_t(m.index(e, "live_cells"))]->grid_pass->live_tiles().download<std::uint32_t>();
  std::vector<std::uint32_t> cells;
  for (std::uint32_t k = 0; k < list[shaders::kLiveCount]; ++k)
    for (std::uint32_t l = 0; l < shaders::kLiveTileCells; ++l)
      cells.push_back(
          shaders::live_tile_cell(list[shaders::kLiveHeaderWords + k], l, list[shaders::kLiveColumns]));
  return cells;
}

void set_trace_order(FramePipeline& pipeline, renderer::TraceOrder order) {
  auto& m = Access::impl(pipeline);
  m.forced_order = order;
  m.settings.live_cells = order == renderer::TraceOrder::Live;
}

namespace {
// Writes the current mappings and a grid image into level 0 of eye `eye`'s mip chain; the
// eye's index. `who` names the caller in the error for a grid of the wrong size.
int upload_level0(FramePipeline& pipeline, core::Eye eye, const std::vector<glm::vec4>& grid, const char* who) {
  auto& m = Access::impl(pipeline);
  const int i = m.index(eye, who);
  if (grid.size() != m.eyes[std::size_t(i)]->cells)
    throw core::InputError(std::string(who) + ": grid size differs from the padded grid");
  m.write_mappings();
  m.resolve->level0(i).upload(grid);
  return i;
}
}  // namespace

core::Image resolve_grid(FramePipeline& pipeline, core::Eye eye, const std::vector<glm::vec4>& grid, bool blur) {
  auto& m = Access::impl(pipeline);
  upload_level0(pipeline, eye, grid, "resolve_grid");
  m.ctx.submit_and_wait([&](VkCommandBuffer cmd) { m.resolve->record_resolve(cmd, m.parity, blur, m.settings); });
  return pipeline.image(eye);
}

std::vector<glm::vec4> resolve_grid_coords(FramePipeline& pipeline, core::Eye eye) {
  auto& m = Access::impl(pipeline);
  const int i = m.index(eye, "resolve_grid_coords");
  m.write_mappings();
  m.ctx.submit_and_wait([&](VkCommandBuffer cmd) { m.resolve->record_resample(cmd, m.parity, m.settings, true); });
  std::vector<glm::vec4> v = m.resolve->screen(i).download<glm::vec4>();
  const core::View& view = m.eyes[std::size_t(i)]->base_view;
  v.resize(std::size_t(view.width()) * view.height());
  return v;
}

core::Image blur_image(FramePipeline& pipeline, core::Eye eye, const core::Image& image) {
  auto& m = Access::impl(pipeline);
  const int i = m.index(eye, "blur_image");
  const core::View& v = m.eyes[std::size_t(i)]->base_view;
  if (image.width != v.width() || image.height != v.height())
    throw core::InputError("blur_image: the image's size differs from the eye's raster");
  m.write_mappings();
  m.resolve->screen(i).upload(image.pixels);
  m.ctx.submit_and_wait([&](VkCommandBuffer cmd) { m.resolve->record_blur(cmd, m.settings); });
  return pipeline.image(eye);
}

std::vector<glm::vec4> blur_grid(FramePipeline& pipeline, core::Eye eye, const std::vector<glm::vec4>& grid) {
  auto& m = Access::impl(pipeline);
  const int i = upload_level0(pipeline, eye, grid, "blur_grid");
  m.ctx.submit_and_wait([&](VkCommandBuffer cmd) { m.resolve->record_grid_blur(cmd, m.settings); });
  std::vector<glm::vec4> out = m.resolve->level0(i).download<glm::vec4>();
  out.resize(grid.size());
  return out;
}

namespace {
// One submission holding what `record` records: its GPU time (timestamps) and the process's CPU time.
template <class Impl, class Record>
KernelTime time_submission(Impl& m, Record&& record) {
  KernelTime t;
  const double cpu0 = process_cpu_ms();
  m.ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    m.timer.begin(cmd);
    record(cmd);
    m.timer.stage(cmd, "kernel");
  });
  t.cpu_ms = process_cpu_ms() - cpu0;
  if (const auto stages = m.timer.read()) t.gpu_ms = double(stages->front().duration_ns()) * 1e-6;
  return t;
}
}  // namespace

ResolveKernelTimes time_resolve(FramePipeline& pipeline, bool blur) {
  auto& m = Access::impl(pipeline);
  const auto time = [&](auto&& record) { return time_submission(m, record); };
  ResolveKernelTimes t;
  t.copy = time([&](VkCommandBuffer cmd) {
    std::vector<const gpu::Buffer*> finals;
    for (std::size_t i = 0; i < m.eyes.size(); ++i) finals.push_back(&m.post->final_color(int(i), m.parity));
    m.resolve->record_copy(cmd, finals);
  });
  KernelTime grid_blur;
  if (blur) grid_blur = time([&](VkCommandBuffer cmd) { m.resolve->record_grid_blur(cmd, m.settings); });
  t.mip = time([&](VkCommandBuffer cmd) { m.resolve->record_mips(cmd); });
  t.resample = time([&](VkCommandBuffer cmd) { m.resolve->record_resample(cmd, m.parity, m.settings); });
  if (blur) t.blur = time([&](VkCommandBuffer cmd) { m.resolve->record_blur(cmd, m.settings); });
  t.blur.gpu_ms += grid_blur.gpu_ms, t.blur.cpu_ms += grid_blur.cpu_ms;
  return t;
}

ReconKernelTimes time_reconstruct(FramePipeline& pipeline, std::uint32_t frame) {
  auto& m = Access::impl(pipeline);
  if (m.frames_done == 0) throw core::InputError("time_reconstruct: no frame rendered yet");
  const auto time = [&](auto&& record) { return time_submission(m, record); };
  const int p = m.parity;
  const bool history = m.frames_done > 1;
  const bool stereo = m.eyes.size() == 2;
  const bool fresh[2] = {true, true};
  m.write_mappings();
  const std::array<bool, 2> unmoved{};  // as a moving view: reprojected (time_reconstruct)
  ReconKernelTimes t;
  t.accumulate = time([&](VkCommandBuffer cmd) {
    m.accumulation->record(cmd, p, history, std::span(fresh, m.eyes.size()), std::span(unmoved.data(), m.eyes.size()),
                           m.settings);
  });
  t.share = time([&](VkCommandBuffer cmd) {
    m.gather->record(cmd, p, stereo && m.settings.share != reconstruct::StereoShare::Off, m.settings);
  });
  if (m.bmfr)
    t.fit = time([&](VkCommandBuffer cmd) {
      m.bmfr->record(cmd, p, frame,
                     m.settings.block_offsets ? reconstruct::bmfr_block_offset(frame) : glm::ivec2(0),
                     m.settings.noise);
    });
  t.post = time([&](VkCommandBuffer cmd) { m.post->record_post(cmd, p, history, m.settings); });
  t.taa = time([&](VkCommandBuffer cmd) { m.post->record_taa(cmd, p, history, m.settings); });
  return t;
}

KernelTime time_trace(FramePipeline& pipeline, std::uint32_t frame, renderer::TraceOrder order) {
  auto& m = Access::impl(pipeline);
  if (m.frames_done == 0) throw core::InputError("time_trace: no frame rendered yet");
  renderer::PathConfig cfg = m.path;
  cfg.order = order;
  return time_submission(m, [&](VkCommandBuffer cmd) {
    for (auto& e : m.eyes)
      m.tracer.record(cmd, e->trace, core::View(e->base_view.fov(), e->base_view.width(), e->base_view.height(), e->pose),
                      e->eye, frame, cfg);
  });
}

}  // namespace fovea::pipeline::testing
