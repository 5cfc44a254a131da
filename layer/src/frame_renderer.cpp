// The layer's path-tracing renderer. Fovea's pipeline runs on its own thread, on a compute
// context of its own: on the application's VkDevice with a queue the layer added to it (in
// lockstep, where the application waits for each frame, its session queue), else on a device
// of the layer's own; the render thread never submits to the application's queue while the
// application may. Each finished frame is encoded in the application's format into a slot of
// the application's device memory (through the host only where that device cannot share it).
// xrEndFrame takes the newest finished frame, reprojects it by rotation to the submitted view
// orientations and composites the application's projection views over it (by depth when it
// chains usable depth) into the layer's swapchains: by a compute pass on the application's
// device (the application's images never leave the device), or, where that device cannot or
// the configuration says so, on the host after reading the application's images back.
#include "frame_renderer.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <thread>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "app_device.hpp"
#include "composite.hpp"
#include "fovea/core/clock.hpp"
#include "fovea/core/display.hpp"
#include "fovea/core/error.hpp"
#include "fovea/core/eye_optics.hpp"
#include "fovea/core/stereo_views.hpp"
#include "fovea/gpu/context.hpp"
#include "fovea/pipeline/frame_driver.hpp"
#include "fovea/renderer/trace_choice.hpp"
#include "fovea/renderer/scene_io.hpp"
#include "layer.hpp"
#include "log.hpp"
#include "next_chain.hpp"
#include "slot_writer.hpp"

namespace fovea::layer {
namespace {

double ms_since(core::TimeNs t0) { return core::ns_to_ms(core::now_ns() - t0); }

core::Fov to_fov(const XrFovf& f) { return {f.angleLeft, f.angleRight, f.angleUp, f.angleDown}; }

core::Pose to_pose(const XrPosef& p) {
  core::Pose o;
  o.orientation = glm::normalize(glm::dquat(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z));
  o.position = {p.position.x, p.position.y, p.position.z};
  return o;
}

void xr_check(XrResult r, const char* what) {
  if (XR_FAILED(r)) throw std::runtime_error(std::string(what) + " failed below the layer: XrResult " + std::to_string(int(r)));
}

// The runtime's hidden triangle mesh for stereo view `index` (XR_KHR_visibility_mask, two-call
// idiom) rasterised into `view`, the submitted view's FOV and raster. Throws naming the call
// or the mesh on failure.
core::ViewMask fetch_visibility_mask(PFN_xrGetVisibilityMaskKHR get, XrSession session, std::uint32_t index,
                                     const core::View& view) {
  constexpr XrViewConfigurationType kStereo = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  constexpr XrVisibilityMaskTypeKHR kHidden = XR_VISIBILITY_MASK_TYPE_HIDDEN_TRIANGLE_MESH_KHR;
  // A mesh this large is not a hidden area (the project's runtime serves a few hundred vertices).
  constexpr std::uint32_t kMaxCount = 1u << 20;
  XrVisibilityMaskKHR m{XR_TYPE_VISIBILITY_MASK_KHR};
  xr_check(get(session, kStereo, index, kHidden, &m), "xrGetVisibilityMaskKHR");
  if (m.vertexCountOutput > kMaxCount || m.indexCountOutput > kMaxCount)
    throw std::runtime_error("xrGetVisibilityMaskKHR: a mesh of " + std::to_string(m.vertexCountOutput) +
                             " vertices and " + std::to_string(m.indexCountOutput) + " indices is beyond the layer's limit");
  std::vector<XrVector2f> xr_vertices(m.vertexCountOutput);
  std::vector<std::uint32_t> indices(m.indexCountOutput);
  m.vertexCapacityInput = m.vertexCountOutput;
  m.vertices = xr_vertices.data();
  m.indexCapacityInput = m.indexCountOutput;
  m.indices = indices.data();
  xr_check(get(session, kStereo, index, kHidden, &m), "xrGetVisibilityMaskKHR");
  xr_vertices.resize(m.vertexCountOutput);
  indices.resize(m.indexCountOutput);
  std::vector<glm::vec2> vertices;
  vertices.reserve(xr_vertices.size());
  for (const XrVector2f& v : xr_vertices) vertices.emplace_back(v.x, v.y);
  const std::string what = "the runtime's hidden triangle mesh of view " + std::to_string(index);
  return core::ViewMask::from_hidden_triangles(view, vertices, indices, what.c_str());
}

// Where the runtime's hidden area comes from (XR_KHR_visibility_mask, when enabled below) and
// the generation of its change events the application's frame saw.
struct MaskSource {
  PFN_xrGetVisibilityMaskKHR get = nullptr;
  std::uint64_t generation = 0;
};

// The views the application submitted: FOV, raster from the imageRect, pose (its reference
// space), IPD as the distance between the two view positions.
core::StereoViews submitted_views(const std::vector<AppView>& v) {
  core::StereoViews s;
  for (int e = 0; e < 2; ++e) {
    const AppView& a = v[std::size_t(e)];
    s.eye[std::size_t(e)] = core::View(to_fov(a.fov), a.rect.extent.width, a.rect.extent.height, to_pose(a.pose));
  }
  s.ipd_m = glm::length(s.eye[1].pose().position - s.eye[0].pose().position);
  return s;
}

// What the application thread hands the render thread: the newest submitted views and gaze.
struct TraceRequest {
  std::int64_t id = 0;
  XrTime display_time = 0;
  std::int64_t app_frame_index = 0;
  std::array<XrPosef, 2> poses{};
  bool gaze_from_action = false;
  ActionGaze action_gaze;
  MaskSource masks;
  bool depth = false;  // the application chains depth to both views in a mode that composites by it
};

// A finished path-traced frame, encoded in the application's swapchain format: in `colour`
// and `depth` (the host path), or in a slot of the application's device memory (the GPU path),
// retired when the frame goes.
struct TracedFrame {
  std::int64_t id = 0;
  XrTime traced_for = 0;
  std::int64_t traced_for_frame = 0;
  std::int64_t done_ns = 0;
  std::array<glm::dquat, 2> orientation{};  // the views' orientations it was traced for (the application's space)
  std::array<Pixels8, 2> colour;
  std::array<std::vector<float>, 2> depth;  // view distances (FramePipeline::depth); empty without has_depth
  bool has_depth = false;                    // traced with its depth (in `depth` or the slot)
  std::unique_ptr<SlotLease> slot;           // the GPU path: colour and depth are there instead
  RenderTimes times;
};

// The render thread's side: Fovea's pipeline on its gpu::Context (make_context says where),
// created on the render thread so that the application's first frames do not wait for the
// scene upload and shader setup either.
class PathTracer {
 public:
  // `slots`: the GPU composition's traced-frame slots, which finished frames are written into
  // (null: the host path, frames kept in host memory).
  // `masks`: the runtime's hidden area at the first frame, which the grids are laid out for.
  PathTracer(const LayerConfig& config, const renderer::Scene& scene, const core::StereoViews& views,
             const core::DisplayPreset& display, VkFormat format, XrSession session, const VulkanBinding& vk,
             const AppDevice* slots, const MaskSource& masks)
      : config_(config), format_(format), session_(session), slots_(slots),
        gaze_(std::make_unique<LayerGaze>(config.gaze, display)), ctx_(make_context(vk, slots)),
        // Imported before anything else can fail: the slots' descriptor is the writer's then.
        writer_(shared_ ? std::make_unique<SlotWriter>(
                              *ctx_, shared_->memory,
                              SlotLayout{views[core::Eye::Left].width(), views[core::Eye::Left].height()},
                              slots->traced_slots()->slots(), pixel_format(format))
                        : nullptr),
        // The frame of `fovea render` (pipeline/frame_driver.hpp) on the application's views. A
        // measurement would delay the first traced frame by seconds: the cached choice, or none.
        driver_(std::make_unique<pipeline::FrameDriver>(*ctx_, scene, views,
                                                        pipeline::FrameDriverOptions{config_.frame, false, false},
                                                        first_visibility(masks, views))) {
    shared_.reset();  // its descriptor is the imported memory's now
    if (writer_ && on_app_device_) {
      FOVEA_LAYER_INFO("hand-over: the application's device (the path tracer runs on it, on %s; each traced frame is "
                       "encoded into the application's device memory, no host copy)", placement_.c_str());
    } else if (writer_) {
      FOVEA_LAYER_INFO("hand-over: shared memory (the layer's device encodes each traced frame into the application's "
                       "device memory, no host copy; not on the application's device: %s)", placement_.c_str());
    } else if (slots) {
      FOVEA_LAYER_INFO("hand-over: through the host (read back, encoded, written into the application's device memory): %s",
                       slots->no_shared_slots().c_str());
    }
    FOVEA_LAYER_INFO("rendering scene \"%s\" (from %s) at %dx%d per eye on %s, composite %s, gaze %s, render %s, "
                     "render thread %s, frame %s, tracing %s (%s)",
                     config_.scene.c_str(), config_.origin.c_str(), display.width, display.height,
                     ctx_->info().name.c_str(), composite_name(config_.composite), gaze_->describe().c_str(),
                     config_.lockstep ? "lockstep" : "async", render_priority_name(config_.render_priority).c_str(),
                     pipeline::to_json(config_.frame).dump().c_str(),
                     renderer::tracing_name(driver_->trace_choice().tracing), driver_->trace_choice().why.c_str());
  }

  // Null when stopped while waiting for a free slot.
  std::shared_ptr<const TracedFrame> trace(const TraceRequest& in) {
    auto f = std::make_shared<TracedFrame>();
    RenderTimes& times = f->times;
    const auto t0 = core::now_ns();
    update_visibility(in);
    const auto t_gaze = core::now_ns();
    // Eye poses: the application's view poses (its reference space) placed at the scene's camera.
    std::array<core::Pose, 2> poses;
    const devices::FoveaGaze fg = gaze_->frame(in.display_time, in.gaze_from_action ? &in.action_gaze : nullptr);
    if (in.gaze_from_action != gaze_from_action_) {
      FOVEA_LAYER_INFO("gaze: %s", in.gaze_from_action ? "the eye-gaze action" : gaze_->describe().c_str());
      gaze_from_action_ = in.gaze_from_action;
    }
    if (fg.has_sample) {
      times.gaze_sample_ns = fg.sample_ns;
      times.gaze_receive_ns = fg.receive_ns;
    }
    times.gaze_read_ns = fg.read_ns;
    times.gaze_on_host_clock = !in.gaze_from_action && gaze_->live();
    for (int e = 0; e < 2; ++e) {
      const auto ei = std::size_t(e);
      const core::Pose p = to_pose(in.poses[ei]);
      f->orientation[ei] = p.orientation;
      poses[ei] = driver_->at_camera(p);
    }
    times.gaze_cpu = ms_since(t_gaze);
    // The scene's depth from the first request whose application submits depth on: only depth
    // compositing reads it, and it costs the resample a read, a transform and a store per pixel.
    if (in.depth) driver_->enable_depth_output();
    f->has_depth = driver_->depth_output();
    times.frame = driver_->step(std::uint32_t(in.id), fg, poses, times.gaze_cpu).times;
    // Counted by the grid pass (no read-back); the hidden ones while a mask is set.
    {
      const pipeline::FramePipeline& p = driver_->pipeline();
      times.samples_traced = p.traced_cells(core::Eye::Left) + p.traced_cells(core::Eye::Right);
      if (masks_[0] || masks_[1]) times.samples_hidden = p.hidden_cells(core::Eye::Left) + p.hidden_cells(core::Eye::Right);
    }
    const auto r0 = core::now_ns();
    if (writer_) {
      // Encoded into a slot by the layer's device, in the application's device memory.
      const std::shared_ptr<SlotPool> pool = slots_->traced_slots();
      const int slot = pool->claim();
      if (slot < 0) return nullptr;
      f->slot = std::make_unique<SlotLease>(pool, slot);
      const pipeline::FramePipeline& p = driver_->pipeline();
      std::array<SlotWriter::Eye, 2> eyes;
      for (int e = 0; e < 2; ++e)
        eyes[std::size_t(e)] = {&p.screen_buffer(core::Eye(e)), f->has_depth ? &p.depth_buffer(core::Eye(e)) : nullptr};
      writer_->write(eyes, slot);
      times.handover = on_app_device_ ? "application-device" : "shared-memory";
      times.readback_cpu = ms_since(r0);
      return finish(std::move(f), in, t0);
    }
    for (int e = 0; e < 2; ++e) {
      const core::Image linear = driver_->pipeline().image(core::Eye(e));
      times.host_bytes += std::int64_t(linear.pixels.size() * sizeof(linear.pixels[0]));
      f->colour[std::size_t(e)] = encode_scene(linear, pixel_format(format_));
      times.host_bytes += std::int64_t(f->colour[std::size_t(e)].data.size());  // written into the app's memory
      if (f->has_depth) {
        f->depth[std::size_t(e)] = driver_->pipeline().depth(core::Eye(e));
        times.host_bytes += 2 * std::int64_t(f->depth[std::size_t(e)].size() * sizeof(float));  // read, written
      }
    }
    times.handover = slots_ ? "host-slot" : "host";
    if (slots_) {
      // Into the application's device memory here, so that xrEndFrame copies no frame. The
      // slot is free: no pass reads it until the frame is published.
      const std::shared_ptr<SlotPool> pool = slots_->traced_slots();
      const int slot = pool->claim();
      if (slot < 0) return nullptr;
      f->slot = std::make_unique<SlotLease>(pool, slot);
      for (int e = 0; e < 2; ++e) {
        const auto ei = std::size_t(e);
        std::memcpy(slots_->slot_colour(slot, e), f->colour[ei].data.data(), f->colour[ei].data.size());
        if (!f->depth[ei].empty())
          std::memcpy(slots_->slot_depth(slot, e), f->depth[ei].data(), f->depth[ei].size() * sizeof(float));
        f->colour[ei] = {};
        f->depth[ei] = {};
      }
    }
    times.readback_cpu = ms_since(r0);
    return finish(std::move(f), in, t0);
  }

 private:
  std::shared_ptr<const TracedFrame> finish(std::shared_ptr<TracedFrame> f, const TraceRequest& in, core::TimeNs t0) {
    f->times.total = ms_since(t0);
    f->id = in.id;
    f->traced_for = in.display_time;
    f->traced_for_frame = in.app_frame_index;
    f->done_ns = core::now_ns();
    return f;
  }

  // The path tracer's device. Where the application's device exported the slots (the
  // hand-over without the host): that device itself, on the queue the layer added to it, or,
  // rendering in lockstep, on the session queue (every submission then happens while the
  // application waits in xrEndFrame, where OpenXR lets a runtime use that queue); else a
  // device of its own on the same physical device, importing them. Without an export, the
  // automatic choice.
  std::unique_ptr<gpu::Context> make_context(const VulkanBinding& vk, const AppDevice* slots) {
    shared_ = slots ? slots->shared_slots() : std::nullopt;
    if (!shared_) return std::make_unique<gpu::Context>();
    try {
      gpu::GivenDevice given{vk.instance, vk.physical_device, vk.device};
      given.instance_api_version = vk.added.instance_api_version;
      given.device_extensions = vk.added.extensions;
      if (vk.added.layer_queue) {
        given.queue_family = vk.added.layer_queue->family;
        given.queue_index = vk.added.layer_queue->index;
        placement_ = "its own queue (family " + std::to_string(given.queue_family) + ", index " +
                     std::to_string(given.queue_index) + ")";
      } else if (config_.lockstep) {
        given.queue_family = vk.queue_family;
        given.queue_index = vk.queue_index;
        placement_ = "the session queue, inside xrEndFrame (lockstep rendering; no queue of its own: " +
                     vk.added.no_layer_queue + ")";
      } else {
        placement_ = "no queue of its own there (" + vk.added.no_layer_queue + ")";
      }
      if (vk.added.layer_queue || config_.lockstep) {
        try {
          auto ctx = std::make_unique<gpu::Context>(given);
          on_app_device_ = true;
          return ctx;
        } catch (const core::InputError& e) {
          placement_ = e.what();
        }
      }
      gpu::ContextOptions o;
      o.device_uuid = shared_->device_uuid;
      o.external_memory_fd = true;
      return std::make_unique<gpu::Context>(o);
    } catch (...) {
      close(shared_->memory.fd);
      throw;
    }
  }
  // The runtime's hidden area for the submitted views, so that each eye's grid is laid out
  // for the pixels it leaves (a Visual-Polar grid then traces its budget with the cells its
  // layout gives them): fetched at the first frame, before the pipeline exists, and after
  // each change event (the grids laid out again, the history starting over). A failed fetch
  // is reported and leaves the previous mask (none at first): culling saves work, the image
  // is right without it.
  const pipeline::EyeMasks& first_visibility(const MaskSource& masks, const core::StereoViews& views) {
    if (!masks.get) return masks_;
    mask_generation_ = masks.generation;
    for (core::Eye eye : {core::Eye::Left, core::Eye::Right})
      masks_[std::size_t(eye)] = fetch_visibility(masks, views, eye, "the grid laid out for the pixels it leaves");
    return masks_;
  }
  void update_visibility(const TraceRequest& in) {
    if (!in.masks.get || mask_generation_ == in.masks.generation) return;
    mask_generation_ = in.masks.generation;
    bool fetched = false;
    for (core::Eye eye : {core::Eye::Left, core::Eye::Right})
      if (auto mask = fetch_visibility(in.masks, driver_->views(), eye, "the grid laid out again from this frame on")) {
        masks_[std::size_t(eye)] = std::move(mask);
        fetched = true;
      }
    if (fetched) driver_->set_visibility(masks_);
  }
  std::optional<core::ViewMask> fetch_visibility(const MaskSource& masks, const core::StereoViews& views, core::Eye eye,
                                                 const char* how) {
    try {
      core::ViewMask mask = fetch_visibility_mask(masks.get, session_, std::uint32_t(eye), views[eye]);
      FOVEA_LAYER_INFO("visibility mask of the %s view: %.1f%% of its pixels hidden, not traced (%s)", core::eye_name(eye),
                       100.0 * mask.hidden_fraction(), how);
      return mask;
    } catch (const std::exception& ex) {
      FOVEA_LAYER_WARN("visibility mask of the %s view not used: %s", core::eye_name(eye), ex.what());
      return std::nullopt;
    }
  }

  const LayerConfig& config_;
  const VkFormat format_;
  const XrSession session_;
  const AppDevice* slots_;
  std::optional<AppDevice::SharedSlots> shared_;  // the slots' memory until writer_ imports it
  bool on_app_device_ = false;  // the path tracer runs on the application's VkDevice
  std::string placement_;       // on which of its queues, or why not
  std::unique_ptr<LayerGaze> gaze_;
  bool gaze_from_action_ = false;
  std::optional<std::uint64_t> mask_generation_;  // of the mask fetched last (none yet)
  pipeline::EyeMasks masks_;                      // the runtime's hidden area the grids are laid out for
  std::unique_ptr<gpu::Context> ctx_;
  std::unique_ptr<SlotWriter> writer_;  // the shared-memory hand-over (null: through the host)
  std::unique_ptr<pipeline::FrameDriver> driver_;
};

// The calling thread's scheduling set to `p`; the reason on failure, else empty.
std::string lower_priority(const RenderPriority& p) {
  const auto tid = static_cast<pid_t>(syscall(SYS_gettid));
  if (p.idle) {
    const sched_param none{};
    if (sched_setscheduler(tid, SCHED_IDLE, &none) != 0) return std::strerror(errno);
  } else if (setpriority(PRIO_PROCESS, static_cast<id_t>(tid), p.nice) != 0) {
    return std::strerror(errno);
  }
  return {};
}

// The angle (degrees) of a rotation.
double rotation_deg(const glm::dquat& q) {
  return glm::degrees(2.0 * std::acos(std::min(1.0, std::abs(q.w))));
}

class PathTraceRenderer final : public FrameRenderer {
 public:
  PathTraceRenderer(const LayerConfig& config, const VulkanBinding& vk, const Dispatch& next, XrSession session)
      : config_(config), next_(next), session_(session), scene_(renderer::load_scene(config.scene)),
        vk_(vk), app_(vk) {
    for (const auto& w : scene_.warnings) FOVEA_LAYER_WARN("scene %s: %s", config.scene.c_str(), w.c_str());
    // Tests slow the render thread down to show that the application never waits for it.
    if (const char* d = std::getenv("FOVEA_LAYER_TEST_RENDER_DELAY_MS")) test_delay_ = std::chrono::milliseconds(std::atoll(d));
  }

  ~PathTraceRenderer() override {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    if (const auto slots = app_.traced_slots()) slots->stop();  // a render thread waiting for a slot
    if (thread_.joinable()) thread_.join();
    try {
      app_.finish();  // a composition pass may still write the swapchain images destroyed below
    } catch (const std::exception& e) {
      FOVEA_LAYER_ERROR("the last composition pass did not finish: %s", e.what());
    }
    for (Eye& e : eyes_)
      if (e.swapchain != XR_NULL_HANDLE) next_.xrDestroySwapchain(e.swapchain);
  }

  int finish_composition(VkImage image) override { return app_.finish_image(image); }
  void forget_images(const std::vector<VkImage>& images) override { app_.forget_images(images); }

  const XrFrameEndInfo* end_frame(const FrameInput& in, Shown& shown) override {
    if (in.app_views.size() != 2) return nullptr;  // only stereo projection layers are replaced
    if (!thread_.joinable()) start(in);
    const XrRect2Di& r0 = in.app_views[0].rect;
    for (const AppView& v : in.app_views)
      if (v.rect.extent.width != r0.extent.width || v.rect.extent.height != r0.extent.height || v.format != format_)
        throw std::runtime_error("the application changed its projection views' size or format during the session");

    TraceRequest req;
    req.display_time = in.display_time;
    req.app_frame_index = in.app_frame_index;
    for (std::size_t e = 0; e < 2; ++e) req.poses[e] = in.app_views[e].pose;
    req.gaze_from_action = in.gaze_from_action;
    req.action_gaze = in.action_gaze;
    req.masks = {in.get_visibility_mask, in.visibility_mask_generation};
    req.depth = config_.composite != Composite::SceneOnly && in.app_views[0].depth && in.app_views[1].depth;
    {
      // Asynchronous: never wait for the render thread. At its low priority it may hold the
      // mailbox while it waits for a core (priority inversion); a frame that finds the mailbox
      // taken shows the frame seen last and does not hand its views over (the next frame's are
      // newer anyway).
      std::unique_lock lock(mutex_, std::defer_lock);
      if (config_.lockstep)
        lock.lock();
      else
        static_cast<void>(lock.try_lock());
      if (lock.owns_lock()) {
        if (!error_.empty()) throw std::runtime_error("the render thread failed: " + error_);
        req.id = next_request_++;
        pending_ = req;  // replaces a request the thread has not picked up: only the newest views count
        wake_.notify_all();
        if (config_.lockstep) {
          // The render thread may need a slot that only this thread gives back.
          app_.release_retired_slots();
          constexpr auto kLimit = std::chrono::minutes(10);
          if (!done_.wait_for(lock, kLimit, [&] { return !error_.empty() || (newest_ && newest_->id >= req.id); }))
            throw std::runtime_error("lockstep rendering: the render thread did not finish a frame in 10 minutes");
          if (!error_.empty()) throw std::runtime_error("the render thread failed: " + error_);
        }
        seen_ = newest_;
      }
    }
    const std::shared_ptr<const TracedFrame> frame = seen_;
    if (!frame) return nullptr;  // nothing traced yet: the application's own frame
    const auto t0 = core::now_ns();
    const XrFrameEndInfo* out = compose(in, *frame, shown);
    shown.times.transfer = ms_since(t0);
    return out;
  }

 private:
  struct Eye {
    XrSwapchain swapchain = XR_NULL_HANDLE;
    std::vector<VkImage> images;
  };

  void run() {
    pthread_setname_np(pthread_self(), "fovea-render");
    // Below the application's threads, before the render device exists: on a CPU device
    // (lavapipe) the device's worker threads do the path tracing and would otherwise take the
    // cores the application's frame loop needs. Linux threads inherit the scheduling policy and
    // the per-thread nice value of the thread that creates them, and lavapipe creates its
    // rasteriser and compute threads with the VkInstance's physical device and the VkDevice
    // (gpu::Context, created below on this thread). The composition pass runs on the
    // application's device, whose threads keep the application's priority.
    if (const std::string failed = lower_priority(config_.render_priority); !failed.empty())
      FOVEA_LAYER_WARN("render thread: cannot set %s (%s); it competes with the application's threads",
                       render_priority_name(config_.render_priority).c_str(), failed.c_str());
    std::unique_ptr<PathTracer> tracer;
    try {
      tracer = std::make_unique<PathTracer>(config_, scene_, views_in_, display_, format_, session_, vk_,
                                            app_.gpu_composition() ? &app_ : nullptr, first_masks_);
      for (;;) {
        TraceRequest req;
        {
          std::unique_lock lock(mutex_);
          wake_.wait(lock, [&] { return stop_ || pending_.has_value(); });
          if (stop_) return;
          if (test_delay_.count() > 0 && wake_.wait_for(lock, test_delay_, [&] { return stop_; })) return;
          req = *pending_;  // the newest, also when it arrived during the delay
          pending_.reset();
        }
        std::shared_ptr<const TracedFrame> f = tracer->trace(req);
        if (!f) return;  // stopped
        {
          // The frame it replaces is freed after the unlock: at a low priority this thread
          // may wait long for a core, and the application must never wait for it on the lock.
          std::lock_guard lock(mutex_);
          newest_.swap(f);
        }
        done_.notify_all();
      }
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex_);
      error_ = e.what();
    }
    done_.notify_all();
  }

  // The traced frame reprojected (rotation only) from the orientations it was traced for to
  // the submitted ones, the application's pixels composited over it, written into the
  // layer's swapchains (on the application's device when it can, else on the host); the
  // application's frame with its projection layer replaced.
  const XrFrameEndInfo* compose(const FrameInput& in, const TracedFrame& f, Shown& shown) {
    shown.frame = f.id;
    shown.traced_for_ns = f.traced_for;
    shown.traced_for_frame = f.traced_for_frame;
    shown.done_ns = f.done_ns;
    shown.times = f.times;
    const bool scene_only = config_.composite == Composite::SceneOnly;
    // A frame traced before the application first chained depth has none: the configured mode.
    const bool by_depth = !scene_only && composite_by_depth(in) && f.has_depth;
    const bool on_gpu = app_.gpu_composition();
    const std::int64_t readbacks = app_.host_readbacks();
    std::array<EyeComposition, 2> eyes;
    for (int e = 0; e < 2; ++e) {
      const auto ei = std::size_t(e);
      EyeComposition& c = eyes[ei];
      c.traced = &f.colour[ei];
      c.traced_view = views_in_[core::Eye(e)];
      c.out_view = core::View(to_fov(in.app_views[ei].fov), c.traced_view.width(), c.traced_view.height());
      c.to_traced = glm::conjugate(f.orientation[ei]) * to_pose(in.app_views[ei].pose).orientation;
      c.app_view = core::View(to_fov(in.app_views[ei].fov), in.app_views[ei].rect.extent.width,
                              in.app_views[ei].rect.extent.height);
      if (by_depth) {
        c.traced_depth = &f.depth[ei];
        c.depth_range = in.app_views[ei].depth->range;
      }
      shown.reprojected_deg = std::max(shown.reprojected_deg, rotation_deg(c.to_traced));
    }
    CompositionRule rule;
    rule.mode = config_.composite;
    if (config_.app_background)
      rule.background = std::array<std::uint8_t, 3>{std::uint8_t((*config_.app_background)[0]),
                                                    std::uint8_t((*config_.app_background)[1]),
                                                    std::uint8_t((*config_.app_background)[2])};
    rule.blend = layer_blend(in.app_frame->layers[in.projection_layer]->layerFlags, pixel_format(format_));
    const auto t_acquire = core::now_ns();
    std::vector<VkImage> targets;
    for (Eye& eye : eyes_) {
      std::uint32_t index = 0;
      xr_check(next_.xrAcquireSwapchainImage(eye.swapchain, nullptr, &index), "xrAcquireSwapchainImage");
      XrSwapchainImageWaitInfo wi{XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO};
      wi.timeout = XR_INFINITE_DURATION;
      xr_check(next_.xrWaitSwapchainImage(eye.swapchain, &wi), "xrWaitSwapchainImage");
      if (index >= eye.images.size()) throw std::runtime_error("the runtime acquired an unknown swapchain image");
      targets.push_back(eye.images[index]);
    }
    const auto t_compose = core::now_ns();
    shown.acquire_ms = core::ns_to_ms(t_compose - t_acquire);
    if (on_gpu) {
      std::array<AppDevice::GpuEye, 2> jobs;
      for (std::size_t e = 0; e < 2; ++e)
        jobs[e] = {eyes[e], {in.app_views[e].image, in.app_views[e].array_index, in.app_views[e].rect},
                   by_depth ? in.app_views[e].depth : std::nullopt, targets[e]};
      if (!f.slot) throw std::logic_error("a traced frame without a slot on the GPU path");
      app_.composite_gpu(f.slot->slot(), jobs, rule);
      shown.traced_slot = f.slot->slot();
      const AppDevice::GpuStats n = app_.gpu_stats();
      shown.recordings = n.recordings;
      shown.descriptor_updates = n.descriptor_updates;
      shown.reuse_waits = n.reuse_waits;
      shown.acquire_waits = n.acquire_waits;
      shown.submit_ms = n.submit_ms;
      shown.submit_preemptions = n.submit_preemptions;
    } else {
      compose_on_host(in, eyes, rule, targets);
    }
    shown.composited_on_gpu = on_gpu;
    shown.host_readbacks = app_.host_readbacks() - readbacks;
    const auto t_release = core::now_ns();
    shown.compose_ms = core::ns_to_ms(t_release - t_compose);
    for (Eye& eye : eyes_) xr_check(next_.xrReleaseSwapchainImage(eye.swapchain, nullptr), "xrReleaseSwapchainImage");
    shown.release_ms = ms_since(t_release);

    // The application's frame with its stereo projection layer replaced by the layer's.
    const auto* app_proj = reinterpret_cast<const XrCompositionLayerProjection*>(in.app_frame->layers[in.projection_layer]);
    projection_ = *app_proj;  // its next chain too
    projection_.viewCount = 2;
    chains_.clear();
    projection_.views = views_.data();
    for (int e = 0; e < 2; ++e) {
      const auto ei = std::size_t(e);
      views_[ei] = {XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW};
      // Every structure the application chained, but the depth: it describes its image, not this one.
      std::size_t lost = 0;
      views_[ei].next = chains_.without(app_proj->views[ei].next, XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR, &lost);
      if (lost && !chain_noted_)
        FOVEA_LAYER_WARN("%zu structure(s) of a type the layer does not know precede the depth chained to a "
                         "projection view: they are not passed on", lost);
      chain_noted_ |= lost > 0;
      views_[ei].pose = in.app_views[ei].pose;
      views_[ei].fov = in.app_views[ei].fov;
      views_[ei].subImage.swapchain = eyes_[ei].swapchain;
      views_[ei].subImage.imageRect = {{0, 0}, {views_in_[core::Eye(e)].width(), views_in_[core::Eye(e)].height()}};
    }
    layers_.assign(in.app_frame->layers, in.app_frame->layers + in.app_frame->layerCount);
    layers_[in.projection_layer] = reinterpret_cast<const XrCompositionLayerBaseHeader*>(&projection_);
    frame_ = *in.app_frame;
    frame_.layers = layers_.data();
    return &frame_;
  }

  // The host path: the application's images (and depths, when compositing by depth) read
  // back, composited on the CPU, uploaded into `targets`.
  void compose_on_host(const FrameInput& in, std::array<EyeComposition, 2>& eyes, const CompositionRule& rule,
                       const std::vector<VkImage>& targets) {
    std::vector<AppDevice::Read> reads;
    for (const AppView& v : in.app_views) reads.push_back({v.image, v.array_index, v.rect});
    const std::vector<Pixels8> app = rule.mode == Composite::SceneOnly ? std::vector<Pixels8>{} : app_.read(reads);
    const std::vector<std::vector<float>> app_depth =
        eyes[0].traced_depth ? app_.read_depth({*in.app_views[0].depth, *in.app_views[1].depth})
                             : std::vector<std::vector<float>>{};
    std::array<Pixels8, 2> out;
    for (std::size_t e = 0; e < 2; ++e) {
      EyeComposition& c = eyes[e];
      c.app = app.empty() ? nullptr : &app[e];
      c.app_depth = app_depth.empty() ? nullptr : &app_depth[e];
      out[e] = compose_eye(c, rule);
    }
    app_.write(targets, {&out[0], &out[1]});
  }

  // Whether this frame composites by depth: the application chained depth to both views and
  // the layer can use it (a format it decodes, the colour rect's size); else the configured
  // mode composites. The decision is logged once.
  bool composite_by_depth(const FrameInput& in) {
    const AppView &l = in.app_views[0], &r = in.app_views[1];
    if (!l.depth && !r.depth) return false;
    std::string why;
    if (!l.depth || !r.depth) why = "depth is chained to one view only";
    for (std::size_t i = 0; i < 2 && why.empty(); ++i) {
      const AppView& v = in.app_views[i];
      if (!depth_format_supported(v.depth->format))
        why = "depth format " + std::to_string(int(v.depth->format)) + " is not decoded";
      else if (v.depth->rect.extent.width != v.rect.extent.width || v.depth->rect.extent.height != v.rect.extent.height)
        why = "the depth imageRect differs in size from the colour imageRect";
    }
    if (!depth_noted_) {
      if (why.empty())
        FOVEA_LAYER_INFO("the application submits depth: compositing by depth");
      else
        FOVEA_LAYER_WARN("the application submits depth but %s: compositing %s", why.c_str(),
                         composite_name(config_.composite));
      depth_noted_ = true;
    }
    return why.empty();
  }

  // At the first stereo frame: the layer's swapchains in the application's format for its
  // views, then the render thread.
  void start(const FrameInput& in) {
    const AppView& v0 = in.app_views[0];
    format_ = v0.format;
    pixel_format(format_);  // throws for formats the layer cannot composite
    views_in_ = submitted_views(in.app_views);
    first_masks_ = {in.get_visibility_mask, in.visibility_mask_generation};
    // The gaze source sees the submitted views as a display without a lens (nothing else of
    // a preset applies to them).
    display_.name = "openxr-views";
    display_.description = "the application's projection views";
    display_.width = views_in_[core::Eye::Left].width();
    display_.height = views_in_[core::Eye::Left].height();
    display_.fov_left = views_in_[core::Eye::Left].fov();
    display_.fov_right = views_in_[core::Eye::Right].fov();
    display_.ipd_m = views_in_.ipd_m;

    for (Eye& e : eyes_) {
      XrSwapchainCreateInfo ci{XR_TYPE_SWAPCHAIN_CREATE_INFO};
      ci.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
      ci.format = format_;
      ci.sampleCount = 1;
      ci.width = std::uint32_t(views_in_[core::Eye::Left].width());
      ci.height = std::uint32_t(views_in_[core::Eye::Left].height());
      ci.faceCount = ci.arraySize = ci.mipCount = 1;
      xr_check(next_.xrCreateSwapchain(session_, &ci, &e.swapchain), "xrCreateSwapchain");
      std::uint32_t n = 0;
      xr_check(next_.xrEnumerateSwapchainImages(e.swapchain, 0, &n, nullptr), "xrEnumerateSwapchainImages");
      std::vector<XrSwapchainImageVulkanKHR> imgs(n, {XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR});
      xr_check(next_.xrEnumerateSwapchainImages(e.swapchain, n, &n,
                                                reinterpret_cast<XrSwapchainImageBaseHeader*>(imgs.data())),
               "xrEnumerateSwapchainImages");
      for (const auto& i : imgs) e.images.push_back(i.image);
    }
    if (!config_.gpu_compositor) {
      FOVEA_LAYER_INFO("composition: on the host (configured)");
    } else {
      try {
        app_.enable_gpu_composition(views_in_[core::Eye::Left].width(), views_in_[core::Eye::Left].height());
        FOVEA_LAYER_INFO("composition: on the GPU (a compute pass on the application's device, session queue family %u)",
                         vk_.queue_family);
      } catch (const std::exception& e) {
        FOVEA_LAYER_WARN("composition: on the host, the application's device cannot composite: %s", e.what());
      }
    }
    thread_ = std::thread([this] { run(); });
  }

  // Set at construction or in start() before the render thread exists; read-only after.
  LayerConfig config_;
  const Dispatch& next_;
  XrSession session_;
  renderer::Scene scene_;
  core::StereoViews views_in_;  // the traced views: FOV, raster (the first frame's imageRect), pose, IPD
  MaskSource first_masks_;      // the runtime's hidden area as the first frame saw it
  core::DisplayPreset display_;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  const VulkanBinding vk_;  // the application's device, for the path tracer's placement
  std::chrono::milliseconds test_delay_{0};

  // The mailbox between the application's xrEndFrame and the render thread; held only to
  // hand a request or a finished frame over, never across a render or a call down the chain.
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::optional<TraceRequest> pending_;
  std::shared_ptr<const TracedFrame> newest_;
  std::string error_;  // the render thread's failure (it has stopped)
  bool stop_ = false;
  std::int64_t next_request_ = 0;
  // The newest finished frame xrEndFrame saw (the application's thread only).
  std::shared_ptr<const TracedFrame> seen_;
  std::thread thread_;

  // xrEndFrame's composition (the application's thread).
  AppDevice app_;
  bool depth_noted_ = false;  // the depth decision was logged
  bool chain_noted_ = false;  // a view's next chain could not be kept whole (logged once)
  ChainCopies chains_;        // the views' next chains, this frame
  std::array<Eye, 2> eyes_;
  XrCompositionLayerProjection projection_{XR_TYPE_COMPOSITION_LAYER_PROJECTION};
  std::array<XrCompositionLayerProjectionView, 2> views_{};
  std::vector<const XrCompositionLayerBaseHeader*> layers_;
  XrFrameEndInfo frame_{XR_TYPE_FRAME_END_INFO};
};

}  // namespace

std::unique_ptr<FrameRenderer> make_frame_renderer(const LayerConfig& config, const VulkanBinding& vk,
                                                   const Dispatch& next, XrSession session) {
  if (config.scene.empty()) return nullptr;
  // "handover": "host" is the reason whatever the device was created with (without it the
  // layer does not add the extension, and the device's record would name another reason).
  VulkanBinding binding = vk;
  if (!config.shared_handover) {
    binding.added.no_external_memory = "configured (\"handover\": \"host\")";
  }
  return std::make_unique<PathTraceRenderer>(config, binding, next, session);
}

}  // namespace fovea::layer
