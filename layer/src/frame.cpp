// Frame intercepts: xrWaitFrame/xrBeginFrame/xrEndFrame are timed, each frame's record kept in
// the session's frames-in-flight queue by predicted display time (frame_queue.hpp). Without a
// renderer the application's frame goes down unchanged; with one, the newest path-traced
// frame replaces its projection layer (frame_renderer.hpp). No lock is held across a call
// down the chain or a composition.
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "layer.hpp"
#include "log.hpp"

namespace fovea::layer {
namespace {

// What an intercepted frame call needs of its session, copied under Layer::mutex so that the
// call itself runs without it.
struct SessionRefs {
  const Dispatch* next = nullptr;
  std::shared_ptr<SessionFrames> frames;     // null: a session the layer does not track
  std::shared_ptr<FrameRenderer> renderer;   // null: pass-through or disabled
  EyeGazeSession gaze;
  PFN_xrGetVisibilityMaskKHR get_visibility_mask = nullptr;
  std::uint64_t visibility_mask_generation = 0;
  XrInstance instance = XR_NULL_HANDLE;
  ConvertTimeToTimespec to_timespec = nullptr;  // null: the runtime cannot convert its XrTime
};

SessionRefs refs(XrSession session) {
  std::lock_guard lock(layer().mutex);
  SessionRefs r;
  r.next = next_for_session(session);
  auto it = layer().sessions.find(session);
  if (it == layer().sessions.end() || it->second.disabled) return r;
  const SessionState& s = it->second;
  r.frames = s.frames;
  r.renderer = s.renderer;
  r.gaze = s.gaze;
  r.get_visibility_mask = s.get_visibility_mask;
  r.visibility_mask_generation = s.visibility_mask_generation;
  r.instance = s.instance;
  if (auto i = layer().instances.find(s.instance); i != layer().instances.end()) r.to_timespec = i->second.to_timespec;
  return r;
}

// The record's XrTime values on CLOCK_MONOTONIC, the clock of the layer's own stamps, with the
// runtime's XR_KHR_convert_timespec_time. Without it, or when a conversion fails, they stay
// the runtime's XrTime and the record says so (xr_time_converted false): an XrTime need not be
// CLOCK_MONOTONIC.
void convert_xr_times(const SessionRefs& s, FrameTimes& t) {
  if (!s.to_timespec) return;
  const auto convert = [&](std::int64_t& ns) {
    if (ns <= 0) return true;  // none: nothing to convert
    timespec ts{};
    if (XR_FAILED(s.to_timespec(s.instance, ns, &ts))) return false;
    ns = std::int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
    return true;
  };
  FrameTimes c = t;
  bool ok = convert(c.display_time_ns) && convert(c.shown.traced_for_ns);
  if (!c.shown.times.gaze_on_host_clock)
    ok = ok && convert(c.shown.times.gaze_sample_ns) && convert(c.shown.times.gaze_receive_ns);
  if (!ok) return;
  t = c;
  t.xr_time_converted = true;
}

// An internal failure: the session passes through from now on. Its renderer is released by
// the last reference (the caller's, after its call down).
void disable(XrSession session, const std::exception& e) {
  FOVEA_LAYER_ERROR("internal failure, the layer passes this session through from now on: %s", e.what());
  std::shared_ptr<FrameRenderer> renderer;
  std::lock_guard lock(layer().mutex);
  auto it = layer().sessions.find(session);
  if (it == layer().sessions.end()) return;
  it->second.disabled = true;
  renderer = std::move(it->second.renderer);
}

// A released image of a swapchain of `session` whose rect and array layer lie inside it.
const SwapchainState* usable_sub_image(XrSession session, const XrSwapchainSubImage& sub) {
  const auto sc = layer().swapchains.find(sub.swapchain);
  if (sc == layer().swapchains.end() || sc->second.session != session) return nullptr;
  const SwapchainState& st = sc->second;
  const XrRect2Di& r = sub.imageRect;
  if (st.last_released < 0 || std::size_t(st.last_released) >= st.images.size() || r.offset.x < 0 ||
      r.offset.y < 0 || r.extent.width <= 0 || r.extent.height <= 0 ||
      std::int64_t(r.offset.x) + r.extent.width > std::int64_t(st.info.width) ||
      std::int64_t(r.offset.y) + r.extent.height > std::int64_t(st.info.height) ||
      sub.imageArrayIndex >= st.info.arraySize)
    return nullptr;
  return &st;
}

// The views of an application's stereo projection layer, if the layer can replace it: each
// is a projection view on a swapchain of this session with a released image, its rect inside
// the image and its array layer present, and so is the depth it may chain (with a range
// the specification allows). Otherwise nothing: the application's frame goes down unchanged and
// the runtime reports the application's error, while the layer stays enabled.
std::vector<AppView> replaceable_views(XrSession session, const XrCompositionLayerProjection& p) {
  std::vector<AppView> views;
  if (p.viewCount != 2 || !p.views) return views;
  for (uint32_t v = 0; v < p.viewCount; ++v) {
    const XrCompositionLayerProjectionView& pv = p.views[v];
    if (pv.type != XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW) return {};
    const SwapchainState* st = usable_sub_image(session, pv.subImage);
    if (!st) return {};
    AppView view{st->images[std::size_t(st->last_released)], VkFormat(st->info.format), pv.subImage.imageRect,
                 pv.subImage.imageArrayIndex, pv.pose, pv.fov, std::nullopt};
    for (auto* n = static_cast<const XrBaseInStructure*>(pv.next); n; n = n->next) {
      if (n->type != XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR) continue;
      const auto& d = *reinterpret_cast<const XrCompositionLayerDepthInfoKHR*>(n);
      const SwapchainState* ds = usable_sub_image(session, d.subImage);
      if (!ds || !(ds->info.usageFlags & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT)) return {};
      if (!(d.minDepth >= 0 && d.minDepth <= d.maxDepth && d.maxDepth <= 1 && d.nearZ > 0 && d.farZ > 0 &&
            d.nearZ != d.farZ))
        return {};
      // An empty depth range is valid but says nothing: the configured mode composites.
      if (d.minDepth == d.maxDepth) break;
      const DepthRange range{d.minDepth, d.maxDepth, d.nearZ, d.farZ};
      view.depth = AppDepth{ds->images[std::size_t(ds->last_released)], VkFormat(ds->info.format),
                            d.subImage.imageRect, d.subImage.imageArrayIndex, range};
      break;
    }
    views.push_back(view);
  }
  return views;
}

}  // namespace

XrResult intercept::xrWaitFrame(XrSession session, const XrFrameWaitInfo* info, XrFrameState* state) {
  const SessionRefs s = refs(session);
  if (!s.next) return XR_ERROR_HANDLE_INVALID;
  const std::int64_t t0 = core::now_ns();
  const XrResult r = s.next->xrWaitFrame(session, info, state);
  const std::int64_t t1 = core::now_ns();
  if (XR_SUCCEEDED(r) && s.frames) {
    std::lock_guard lock(s.frames->mutex);
    s.frames->queue.waited(state->predictedDisplayTime, t0, t1);
  }
  return r;
}

XrResult intercept::xrBeginFrame(XrSession session, const XrFrameBeginInfo* info) {
  const SessionRefs s = refs(session);
  if (!s.next) return XR_ERROR_HANDLE_INVALID;
  const XrResult r = s.next->xrBeginFrame(session, info);
  if (XR_SUCCEEDED(r) && s.frames) {
    std::lock_guard lock(s.frames->mutex);
    s.frames->queue.begun(core::now_ns());
  }
  return r;
}

XrResult intercept::xrEndFrame(XrSession session, const XrFrameEndInfo* info) {
  const SessionRefs s = refs(session);
  if (!s.next) return XR_ERROR_HANDLE_INVALID;
  const std::int64_t t_call = core::now_ns();
  // The frame this call ends (its record leaves the queue): a frame begun before, with a valid
  // end info, is one the runtime may accept and the only kind rendered.
  std::optional<FrameTimes> record;
  if (s.frames && info && info->type == XR_TYPE_FRAME_END_INFO) {
    std::lock_guard lock(s.frames->mutex);
    record = s.frames->queue.end(info->displayTime);
  }
  const XrFrameEndInfo* submit = info;
  Shown shown;
  if (s.renderer && record && info->displayTime > 0) {
    FrameInput in;
    in.display_time = info->displayTime;
    in.app_frame_index = record->frame;
    in.app_frame = info;
    {
      // The first stereo projection layer is the one replaced.
      std::lock_guard lock(layer().mutex);
      for (uint32_t i = 0; info->layers && i < info->layerCount; ++i) {
        if (!info->layers[i] || info->layers[i]->type != XR_TYPE_COMPOSITION_LAYER_PROJECTION) continue;
        const auto* p = reinterpret_cast<const XrCompositionLayerProjection*>(info->layers[i]);
        if (p->viewCount != 2 || !p->views) continue;
        in.projection_layer = i;
        in.app_views = replaceable_views(session, *p);
        break;
      }
    }
    in.get_visibility_mask = s.get_visibility_mask;
    in.visibility_mask_generation = s.visibility_mask_generation;
    if (s.gaze.attached()) {
      in.gaze_from_action = true;
      in.action_gaze = locate_eye_gaze(*s.next, s.gaze, info->displayTime);
    }
    try {
      if (const XrFrameEndInfo* replaced = s.renderer->end_frame(in, shown)) submit = replaced;
    } catch (const std::exception& e) {
      disable(session, e);
      submit = info;
      shown = Shown{};
    }
  }
  const std::int64_t t_down = core::now_ns();
  const XrResult r = s.next->xrEndFrame(session, submit);
  const std::int64_t t_return = core::now_ns();
  if (record) {
    FrameTimes& t = *record;
    t.end_call_ns = t_call;
    t.end_return_ns = t_return;
    t.end_down_ns = t_down;
    t.layers = info->layerCount;
    t.projection_views = 0;
    for (uint32_t i = 0; info->layers && i < info->layerCount; ++i)
      if (info->layers[i] && info->layers[i]->type == XR_TYPE_COMPOSITION_LAYER_PROJECTION)
        t.projection_views += reinterpret_cast<const XrCompositionLayerProjection*>(info->layers[i])->viewCount;
    t.replaced = submit != info;
    if (t.replaced) t.shown = shown;
    convert_xr_times(s, t);
    s.frames->log.write(t);
  }
  return r;
}

}  // namespace fovea::layer
