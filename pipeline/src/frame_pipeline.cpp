#include "fovea/pipeline/frame_pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "fovea/core/acuity.hpp"
#include "fovea/core/clock.hpp"
#include "fovea/core/error.hpp"
#include "fovea/gpu/barriers.hpp"
#include "frame_pipeline_impl.hpp"

namespace fovea::pipeline {

namespace {

gpu::Buffer storage(gpu::Context& ctx, VkDeviceSize bytes, const char* name) {
  return gpu::Buffer(ctx, {.size = std::max<VkDeviceSize>(bytes, 16), .usage = gpu::BufferUsage::Storage, .name = name});
}

// Milliseconds since `t0` on the monotonic clock, and restart it.
double lap_ms(core::TimeNs& t0) {
  const core::TimeNs t = core::now_ns();
  const double ms = core::ns_to_ms(t - t0);
  t0 = t;
  return ms;
}

// The raster's largest pixels per degree (a rectilinear raster's pixels subtend the least
// at its corners; the centre is checked too), along x and y.
double max_pixels_per_deg(const core::View& v) {
  double best = 0;
  const double w = v.width(), h = v.height();
  for (const glm::dvec2 c : {glm::dvec2(0.5, 0.5), glm::dvec2(w - 1.5, 0.5), glm::dvec2(0.5, h - 1.5),
                             glm::dvec2(w - 1.5, h - 1.5), glm::dvec2(0.5 * w, 0.5 * h)})
    for (const glm::dvec2 step : {glm::dvec2(1, 0), glm::dvec2(0, 1)})
      best = std::max(best, 1.0 / std::max(core::angle_deg(v.pixel_to_dir(c), v.pixel_to_dir(c + step)), 1e-9));
  return best;
}

std::unique_ptr<EyeState> make_eye(gpu::Context& ctx, renderer::PathTracer& tracer, core::Eye eye,
                                   const core::View& view, const core::DistributionParams& dp,
                                   const std::optional<core::ViewMask>& mask) {
  auto e = std::make_unique<EyeState>();
  e->eye = eye;
  e->base_view = view;
  e->pose = view.pose();
  e->dist = core::make_distribution(core::View(view.fov(), view.width(), view.height()), dp, mask ? &*mask : nullptr);
  if (mask) e->mask.assign(mask->words().begin(), mask->words().end());
  e->hold = core::GridHold(core::GridHold::radius_for_margin(dp.margin_deg));
  if (!e->dist->invertible())
    throw core::InputError(std::string("--distribution: ") + core::distribution_name(dp.kind) +
                           " has no screen-to-grid mapping; the reconstruction needs one");
  e->cells = std::uint32_t(e->dist->padded_columns() * e->dist->padded_rows());
  e->grid_pass = std::make_unique<gpu::GridPass>(ctx, e->cells);  // the list's capacity: no regrowth
  e->grid = storage(ctx, gpu::GridPass::samples_bytes(*e->dist), "recon.grid");
  e->trace = tracer.bind(e->grid,
                         renderer::GridExtent{std::uint32_t(e->dist->padded_columns()),
                                              std::uint32_t(e->dist->padded_rows())},
                         &e->grid_pass->live_tiles());
  return e;
}

// Whether the grid is the display's own raster (full Cartesian, linear fall-off): its cells
// are the pixels, which the resolve reads at their centres.
bool display_raster(const EyeState& e) {
  return e.dist->gpu_params().family == shaders::kFamilyCartesian && e.dist->columns() == e.base_view.width() &&
         e.dist->rows() == e.base_view.height();
}

// The angle from the gaze beyond which the resolve no longer re-modulates with the pixels' own
// albedo: the fovea (within which it does fully) and the distribution's margin, at least 0.5°.
double pixel_albedo_none_deg(const EyeState& e) {
  return core::acuity::kFoveaDeg + std::max(e.dist->params().margin_deg, 0.5);
}

}  // namespace

int FramePipeline::Impl::index(core::Eye e, const char* what) const {
  for (std::size_t i = 0; i < eyes.size(); ++i)
    if (eyes[i]->eye == e) return int(i);
  throw core::InputError(std::string(what) + ": eye not rendered");
}

// Vulkan leaves new memory undefined (lavapipe hands out recycled heap memory), and a buffer
// that a configuration never writes would otherwise read back differently from run to run.
void FramePipeline::Impl::fill(std::uint32_t word) {
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    for (auto& e : eyes) {
      const renderer::TraceOutputs& t = e->trace;
      for (const gpu::Buffer* b : {static_cast<const gpu::Buffer*>(&e->grid), &t.direct(), &t.indirect(), &t.albedo(), &t.normal_depth(),
                                   &t.position_material(), &t.radiance()})
        gpu::fill_buffer(cmd, *b, word);
    }
    accumulation->fill(cmd, word);
    gather->fill(cmd, word);
    if (bmfr) bmfr->fill(cmd, word);
    post->fill(cmd, word);
    resolve->fill(cmd, word);
  });
  // The cells without a sample now hold `word` too: list them for the next two frames.
  for (auto& e : eyes) e->grid_pass->reset_history();
}

FramePipeline::FramePipeline(gpu::Context& ctx, const renderer::GpuScene& scene, const core::StereoViews& views,
                             const core::DistributionParams& distribution, const reconstruct::ReconSettings& settings,
                             const renderer::PathConfig& path, bool mono, const EyeMasks& visibility)
    : impl_(std::make_unique<Impl>(ctx, scene, path, settings)) {
  if (mono && settings.share != reconstruct::StereoShare::Off)
    throw core::InputError("--stereo-share: sharing needs both eyes");
  Impl& m = *impl_;
  for (int i = 0; i < (mono ? 1 : 2); ++i)
    m.eyes.push_back(make_eye(ctx, m.tracer, core::Eye(i), views[core::Eye(i)], distribution, visibility[size_t(i)]));
  if (settings.pixel_albedo && scene.features().textures && !display_raster(*m.eyes[0]))
    m.pixel_albedo = std::make_unique<renderer::DisplayAlbedo>(ctx, scene);
  std::vector<reconstruct::EyeGrid> grids;
  for (auto& e : m.eyes) {
    if (m.pixel_albedo)
      e->primary = m.pixel_albedo->bind(renderer::cone_window_capacity(e->base_view, pixel_albedo_none_deg(*e)));
    const EyeState* o = m.other(*e);
    e->mapping = std::make_unique<reconstruct::GridMapping>(ctx, *e->dist, o ? o->dist.get() : nullptr);
    const renderer::TraceOutputs& t = e->trace;
    grids.push_back({.cells = e->cells,
                     .columns = std::uint32_t(e->dist->columns()),
                     .padded_columns = std::uint32_t(e->dist->padded_columns()),
                     .padded_rows = std::uint32_t(e->dist->padded_rows()),
                     .polar = e->dist->gpu_params().family != shaders::kFamilyCartesian,
                     .width = std::uint32_t(e->base_view.width()),
                     .height = std::uint32_t(e->base_view.height()),
                     .max_pixels_per_deg = max_pixels_per_deg(e->base_view),
                     .mapping = e->mapping.get(),
                     .samples = &e->grid,
                     .direct = &t.direct(),
                     .indirect = &t.indirect(),
                     .normal_depth = &t.normal_depth(),
                     .position_material = &t.position_material(),
                     .albedo = &t.albedo(),
                     .live = &e->grid_pass->live_tiles(),
                     .primary = m.pixel_albedo ? &e->primary.hits() : nullptr});
  }
  // The reconstruction's per-cell kernels over the live tiles, except for a Cartesian raster
  // on a CPU device: lavapipe's SIMD vectors then run down a tile's column, 8 raster rows
  // apart in memory, which took 1.27× the time of a dispatch over every cell (on a polar
  // grid those are neighbours in φ, which the kernels read together: 0.86–1.07×;
  // docs/renderer.md "Live cells").
  m.settings.live_cells = m.eyes[0]->dist->gpu_params().family != shaders::kFamilyCartesian ||
                          ctx.info().type != VK_PHYSICAL_DEVICE_TYPE_CPU;
  m.accumulation = std::make_unique<reconstruct::Accumulation>(ctx, grids, m.tracer.scene().materials());
  m.gather = std::make_unique<reconstruct::StereoGather>(ctx, grids, *m.accumulation);
  if (settings.denoiser == reconstruct::Denoiser::Bmfr)
    m.bmfr = std::make_unique<reconstruct::Bmfr>(ctx, grids, *m.accumulation, *m.gather,
                                                  m.tracer.scene().materials(), settings.bmfr_precision);
  m.post = std::make_unique<reconstruct::PostTaa>(ctx, grids, *m.accumulation, *m.gather, m.bmfr.get(),
                                                  m.pixel_albedo != nullptr);
  m.resolve = std::make_unique<reconstruct::Resolve>(ctx, grids, *m.accumulation, *m.post);
  m.fill(0);
}

FramePipeline::~FramePipeline() = default;

void FramePipeline::reset() {
  impl_->frames_done = 0;
  impl_->landing_left = 0;
  for (auto& e : impl_->eyes) {
    e->dist->restart();  // no σ0 warm start from the frames before
    // The next frame writes parity 0 whichever the last one wrote, so a double-buffered cell
    // may skip a frame: list every cell without a sample as reset for two frames.
    e->grid_pass->reset_history();
  }
}

void FramePipeline::set_visibility(core::Eye eye, const core::ViewMask& mask) {
  EyeState& e = *impl_->eyes[std::size_t(impl_->index(eye, "set_visibility"))];
  e.dist->set_visibility(mask);  // refuses another raster; the budget counts the pixels the mask leaves
  e.mask.assign(mask.words().begin(), mask.words().end());
}

std::vector<std::pair<std::string, double>> FrameTimes::gpu_record() const {
  std::vector<std::pair<std::string, double>> r;
  for (const auto& [name, st] : stages()) r.emplace_back(name, st.gpu_ms);
  r.insert(r.end(), {{"pixel_albedo", pixel_albedo_gpu_ms}, {"accumulate", accumulate_gpu_ms},
                     {"bmfr_fit", bmfr_fit_gpu_ms}, {"post", post_gpu_ms}, {"mip", mip_gpu_ms},
                     {"resample", resample_gpu_ms}, {"blur", blur_gpu_ms}, {"total", gpu_ms()}});
  return r;
}

std::vector<std::pair<std::string, double>> FrameTimes::cpu_record(double gaze_cpu_ms) const {
  std::vector<std::pair<std::string, double>> r{{"gaze", gaze_cpu_ms}};
  for (const auto& [name, st] : stages()) r.emplace_back(name, st.cpu_ms);
  r.insert(r.end(), {{"submit", submit_cpu_ms}, {"wait", wait_cpu_ms}, {"total", gaze_cpu_ms + cpu_ms()}});
  return r;
}

FrameTimes FramePipeline::render(const std::array<core::Pose, 2>& eye_pose, const std::array<glm::dvec3, 2>& gaze,
                                 std::uint32_t frame) {
  Impl& m = *impl_;
  FrameTimes t;
  core::TimeNs t0 = core::now_ns();
  const int p = m.frames_done == 0 ? 0 : 1 - m.parity;
  const bool history = m.frames_done > 0;
  double motion = 0;  // the largest change of an eye's view since the last frame (degrees)
  double jump = 0;    // the largest change of an eye's gaze (degrees)
  for (auto& e : m.eyes) {
    const int i = int(e->eye);
    const core::Pose pose_before = e->pose;
    const glm::dvec3 gaze_before = e->gaze_used;
    e->pose = eye_pose[i];
    if (!history) e->hold.reset();
    t.gaze[i] = e->dist->set_frame(e->hold.place(gaze[i]), frame);
    e->gaze_used = t.gaze[i].used;
    motion = std::max(motion, reconstruct::view_motion_deg(gaze_before, e->gaze_used, pose_before, e->pose));
    if (history) jump = std::max(jump, core::angle_deg(gaze_before, e->gaze_used));
    e->grid_pass->prepare(*e->dist, e->mask);
  }
  // A still view converges (history weights 1/n); a moving one keeps the EMA floors.
  reconstruct::ReconSettings settings = reconstruct::with_history_floors(m.settings, motion);
  t.history_floor = 1.0f - settings.still;
  // The new fovea (and the distribution's margin) traces more samples for the landing's
  // frames, and takes no TAA history on its first.
  const double landing_deg = core::acuity::kFoveaDeg + m.eyes.front()->dist->params().margin_deg;
  if (jump >= reconstruct::kLandingJumpDeg) {
    m.landing_left = reconstruct::kLandingFrames;
    settings.landing_deg = float(landing_deg);
  }
  const bool landing = m.landing_left > 0;
  if (landing) --m.landing_left;
  t.grid.cpu_ms = lap_ms(t0);
  m.write_mappings();
  const std::array<bool, 2> unmoved = m.unmoved();
  t.reconstruct.cpu_ms = lap_ms(t0);
  const bool stereo = m.eyes.size() == 2;
  const bool alternate = stereo && m.settings.share == reconstruct::StereoShare::Alternate;
  // Alternating sharing: only one eye traces indirect diffuse this frame.
  bool fresh[2] = {true, true};
  const std::uint32_t noise = frame + kSeedStride * m.seed;
  for (std::size_t i = 0; i < m.eyes.size(); ++i) fresh[i] = !alternate || int(m.eyes[i]->eye) == int(frame % 2);

  double recording_ms = 0;  // inside submit_and_wait, counted to the stages
  m.ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    const core::TimeNs start = core::now_ns();
    core::TimeNs r0 = start;
    m.timer.begin(cmd);
    for (auto& e : m.eyes) e->grid_pass->record(cmd, e->grid);
    gpu::compute_to_indirect(cmd);
    m.timer.stage(cmd, "grid");
    t.grid.cpu_ms += lap_ms(r0);
    for (std::size_t i = 0; i < m.eyes.size(); ++i) {
      EyeState& e = *m.eyes[i];
      renderer::PathConfig cfg = m.path;
      if (!fresh[i]) cfg.max_bounces = 0;
      cfg.order = m.trace_order();
      // One sample per cell and frame: textures prefiltered at the cell's size, or at half of
      // it on a jittered grid, whose accumulated frames already box-filter them over the cell
      // (a mip bias of −1, as temporal upscalers recommend; docs/reconstruction.md).
      cfg.texture_cone = e.dist->params().jitter ? 0.5 : 1.0;
      if (landing) {
        cfg.boost_spp = m.settings.landing_spp;
        cfg.boost_deg = landing_deg;
      }
      m.tracer.record(cmd, e.trace, core::View(e.base_view.fov(), e.base_view.width(), e.base_view.height(), e.pose),
                      e.eye, noise, cfg);
    }
    gpu::compute_to_compute(cmd);
    m.timer.stage(cmd, "trace");
    if (m.pixel_albedo) {
      for (std::size_t i = 0; i < m.eyes.size(); ++i) {
        EyeState& e = *m.eyes[i];
        const core::View view(e.base_view.fov(), e.base_view.width(), e.base_view.height(), e.pose);
        const double none_deg = pixel_albedo_none_deg(e);
        const renderer::PixelWindow w = renderer::cone_window(view, e.gaze_used, none_deg, e.primary.capacity());
        m.pixel_albedo->record(cmd, e.primary, view, w);
        constexpr double kDeg = std::numbers::pi / 180;
        m.resolve->set_detail(int(i), {w.x0, w.y0, w.width, w.height, float(std::cos(core::acuity::kFoveaDeg * kDeg)),
                                       float(std::cos(none_deg * kDeg))});
      }
      gpu::compute_to_compute(cmd);
      m.timer.stage(cmd, "pixel_albedo");
    }
    t.trace.cpu_ms = lap_ms(r0);
    m.accumulation->record(cmd, p, history, std::span(fresh, m.eyes.size()), std::span(unmoved.data(), m.eyes.size()),
                           settings);
    m.gather->record(cmd, p, stereo && m.settings.share != reconstruct::StereoShare::Off, settings);
    m.timer.stage(cmd, "accumulate");
    if (m.bmfr)
      m.bmfr->record(cmd, p, noise, m.settings.block_offsets ? reconstruct::bmfr_block_offset(noise) : glm::ivec2(0),
                     m.settings.noise);
    m.timer.stage(cmd, "bmfr_fit");
    m.post->record(cmd, p, history, settings);
    m.timer.stage(cmd, "post");
    t.reconstruct.cpu_ms += lap_ms(r0);
    std::vector<const gpu::Buffer*> finals;
    for (std::size_t i = 0; i < m.eyes.size(); ++i) finals.push_back(&m.post->final_color(int(i), p));
    m.resolve->record_copy(cmd, finals);
    m.timer.stage(cmd, "resolve");
    if (m.settings.blur) m.resolve->record_grid_blur(cmd, m.settings);
    m.timer.stage(cmd, "grid_blur");
    m.resolve->record_mips(cmd);
    m.timer.stage(cmd, "mip");
    m.resolve->record_resample(cmd, p, m.settings);
    m.timer.stage(cmd, "resample");
    if (m.settings.blur) m.resolve->record_blur(cmd, m.settings);
    m.timer.stage(cmd, "blur");
    t.resolve.cpu_ms = lap_ms(r0);
    if (m.temporal) {
      m.resolve->record_temporal(cmd, m.temporal_frames > 0);
      m.timer.stage(cmd, "temporal");
    }
    recording_ms = core::ns_to_ms(r0 - start);
  }, &t.wait_cpu_ms);
  t.submit_cpu_ms = std::max(0.0, lap_ms(t0) - recording_ms - t.wait_cpu_ms);
  for (auto& e : m.eyes) e->mapping->advance(e->pose);
  m.parity = p;
  ++m.frames_done;
  if (m.temporal) m.temporal_pairs += m.temporal_frames++ > 0;
  t.reconstruct.cpu_ms += lap_ms(t0);

  if (const auto stages = m.timer.read()) {
    for (const gpu::StageTime& s : *stages) {
      const double ms = double(s.duration_ns()) * 1e-6;
      if (s.name == "temporal") t.temporal_gpu_ms = ms;
      else if (s.name == "grid") t.grid.gpu_ms += ms;
      else if (s.name == "trace") t.trace.gpu_ms += ms;
      else if (s.name == "pixel_albedo") t.trace.gpu_ms += (t.pixel_albedo_gpu_ms = ms);
      else if (s.name == "resolve" || s.name == "grid_blur" || s.name == "mip" || s.name == "resample" || s.name == "blur")
        t.resolve.gpu_ms += ms;
      else t.reconstruct.gpu_ms += ms;
      if (s.name == "accumulate") t.accumulate_gpu_ms = ms;
      if (s.name == "bmfr_fit") t.bmfr_fit_gpu_ms = ms;
      if (s.name == "post") t.post_gpu_ms = ms;
      if (s.name == "mip") t.mip_gpu_ms = ms;
      if (s.name == "resample") t.resample_gpu_ms = ms;
      if (s.name == "blur" || s.name == "grid_blur") t.blur_gpu_ms += ms;
    }
  }
  return t;
}

void FramePipeline::enable_temporal_error() { impl_->temporal = true; }

void FramePipeline::set_seed(std::uint32_t seed) { impl_->seed = seed; }

double FramePipeline::temporal_error(core::Eye e) const {
  const Impl& m = *impl_;
  const int i = m.index(e, "temporal_error");
  if (m.temporal_pairs == 0) return 0;
  const core::View& v = m.eyes[std::size_t(i)]->base_view;
  return m.resolve->temporal_abs_luma_sum(i) / (double(v.width()) * v.height() * m.temporal_pairs);
}

core::Image FramePipeline::image(core::Eye e) const {
  const int i = impl_->index(e, "image");
  const core::View& v = impl_->eyes[std::size_t(i)]->base_view;
  core::Image img(v.width(), v.height());
  img.pixels = impl_->resolve->screen(i).download<glm::vec4>();
  img.pixels.resize(std::size_t(img.width) * img.height);
  return img;
}

void FramePipeline::enable_depth_output() { impl_->resolve->set_depth_output(true); }

// The depth buffers hold what the resample last wrote: nothing unless it writes depth.
static void require_depth(const reconstruct::Resolve& r, const char* what) {
  if (!r.depth_output()) throw core::InputError(std::string(what) + ": the depth output is off (enable_depth_output)");
}

std::vector<float> FramePipeline::depth(core::Eye e) const {
  const int i = impl_->index(e, "depth");
  require_depth(*impl_->resolve, "depth");
  const core::View& v = impl_->eyes[std::size_t(i)]->base_view;
  std::vector<float> d = impl_->resolve->depth(i).download<float>();
  d.resize(std::size_t(v.width()) * std::size_t(v.height()));
  return d;
}

const gpu::Buffer& FramePipeline::screen_buffer(core::Eye e) const {
  return impl_->resolve->screen(impl_->index(e, "screen_buffer"));
}

const gpu::Buffer& FramePipeline::depth_buffer(core::Eye e) const {
  const int i = impl_->index(e, "depth_buffer");
  require_depth(*impl_->resolve, "depth_buffer");
  return impl_->resolve->depth(i);
}

std::vector<shaders::GridSample> FramePipeline::grid_samples(core::Eye eye) const {
  const EyeState& e = *impl_->eyes[std::size_t(impl_->index(eye, "grid_samples"))];
  std::vector<shaders::GridSample> v = e.grid.download<shaders::GridSample>();
  v.resize(e.cells);
  return v;
}

// Counted by the grid pass while it generates the grid: no read-back of the grid.
std::int64_t FramePipeline::traced_cells(core::Eye eye) const {
  return impl_->eyes[std::size_t(impl_->index(eye, "traced_cells"))]->grid_pass->counts().traced;
}

std::int64_t FramePipeline::hidden_cells(core::Eye eye) const {
  return impl_->eyes[std::size_t(impl_->index(eye, "hidden_cells"))]->grid_pass->counts().hidden;
}

IndirectSamples FramePipeline::indirect_samples(core::Eye eye) const {
  const int i = impl_->index(eye, "indirect_samples");
  const auto mean_w = [](const std::vector<glm::vec4>& v) {
    double s = 0;
    long n = 0;
    for (const auto& c : v)
      if (c.w > 0) s += c.w, ++n;
    return n ? s / double(n) : 0.0;
  };
  return {mean_w(impl_->accumulation->indirect(i, impl_->parity).download<glm::vec4>()),
          mean_w(impl_->gather->shared(i).download<glm::vec4>())};
}

const core::SampleDistribution& FramePipeline::distribution(core::Eye eye) const {
  return *impl_->eyes[std::size_t(impl_->index(eye, "distribution"))]->dist;
}

core::View FramePipeline::view(core::Eye eye) const {
  const EyeState& e = *impl_->eyes[std::size_t(impl_->index(eye, "view"))];
  return core::View(e.base_view.fov(), e.base_view.width(), e.base_view.height(), e.pose);
}

int FramePipeline::eyes() const { return int(impl_->eyes.size()); }
const reconstruct::ReconSettings& FramePipeline::settings() const { return impl_->settings; }

}  // namespace fovea::pipeline
