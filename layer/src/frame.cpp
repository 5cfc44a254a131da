// Frame intercepts: xrWaitFrame/xrBeginFrame/xrEndFrame are timed. Without a renderer the
// application's frame goes down unchanged; with one, its layers replace the application's (frame_renderer.hpp).
#include <stdexcept>
#include <vector>

#include "layer.hpp"
#include "log.hpp"

namespace fovea::layer {
namespace {

// Runs layer bookkeeping for a session; an exception disables the layer for the session.
template <class F>
void bookkeeping(XrSession session, F&& f) {
  std::lock_guard lock(layer().mutex);
  auto it = layer().sessions.find(session);
  if (it == layer().sessions.end() || it->second.disabled) return;
  try {
    f(it->second);
  } catch (const std::exception& e) {
    FOVEA_LAYER_ERROR("internal failure, the layer passes this session through from now on: %s", e.what());
    it->second.renderer.reset();
    it->second.disabled = true;
  }
}

// The views of an application's stereo projection layer, if the layer can replace it: each
// is a projection view on a swapchain of this session with a released image, its rect inside
// the image and its array layer present. Otherwise nothing: the application's frame goes down
// unchanged and the runtime reports the application's error, while the layer stays enabled.
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

template <class PFN>
PFN next_fn(XrSession session, PFN Dispatch::*member) {
  std::lock_guard lock(layer().mutex);
  const Dispatch* d = next_for_session(session);
  return d ? d->*member : nullptr;
}

}  // namespace

XrResult intercept::xrWaitFrame(XrSession session, const XrFrameWaitInfo* info, XrFrameState* state) {
  const auto next = next_fn(session, &Dispatch::xrWaitFrame);
  if (!next) return XR_ERROR_HANDLE_INVALID;
  const std::int64_t t0 = now_ns();
  const XrResult r = next(session, info, state);
  const std::int64_t t1 = now_ns();
  if (XR_SUCCEEDED(r))
    bookkeeping(session, [&](SessionState& s) {
      s.current.wait_call_ns = t0;
      s.current.wait_return_ns = t1;
      s.current.display_time_ns = state->predictedDisplayTime;
    });
  return r;
}

XrResult intercept::xrBeginFrame(XrSession session, const XrFrameBeginInfo* info) {
  const auto next = next_fn(session, &Dispatch::xrBeginFrame);
  if (!next) return XR_ERROR_HANDLE_INVALID;
  const XrResult r = next(session, info);
  if (XR_SUCCEEDED(r)) bookkeeping(session, [&](SessionState& s) { s.current.begin_ns = now_ns(); });
  return r;
}

XrResult intercept::xrEndFrame(XrSession session, const XrFrameEndInfo* info) {
  const auto next = next_fn(session, &Dispatch::xrEndFrame);
  if (!next) return XR_ERROR_HANDLE_INVALID;
  const XrFrameEndInfo* submit = info;
  const std::int64_t t_call = now_ns();
  bookkeeping(session, [&](SessionState& s) {
    if (!s.renderer || !info) return;
    FrameInput in;
    in.frame = s.current.frame;
    in.display_time = info->displayTime;
    in.app_frame = info;
    // Only a frame the runtime may accept is rendered: begun, with a valid end info.
    if (info->type != XR_TYPE_FRAME_END_INFO || info->displayTime <= 0 || s.current.begin_ns == 0) return;
    // The first stereo projection layer is the one replaced.
    for (uint32_t i = 0; info->layers && i < info->layerCount; ++i) {
      if (!info->layers[i] || info->layers[i]->type != XR_TYPE_COMPOSITION_LAYER_PROJECTION) continue;
      const auto* p = reinterpret_cast<const XrCompositionLayerProjection*>(info->layers[i]);
      if (p->viewCount != 2 || !p->views) continue;
      in.projection_layer = i;
      in.app_views = replaceable_views(session, *p);
      break;
    }
    in.get_visibility_mask = s.get_visibility_mask;
    in.visibility_mask_generation = s.visibility_mask_generation;
    if (s.gaze.attached()) {
      in.gaze_from_action = true;
      in.action_gaze = locate_eye_gaze(*next_for_session(session), s.gaze, info->displayTime);
    }
    if (const XrFrameEndInfo* replaced = s.renderer->render(in)) submit = replaced;
    s.current.render = s.renderer->times();
  });
  const XrResult r = next(session, submit);
  const std::int64_t t_return = now_ns();
  bookkeeping(session, [&](SessionState& s) {
    FrameTimes& t = s.current;
    t.end_call_ns = t_call;
    t.end_return_ns = t_return;
    t.layers = info ? info->layerCount : 0;
    t.projection_views = 0;
    for (uint32_t i = 0; info && info->layers && i < info->layerCount; ++i)
      if (info->layers[i] && info->layers[i]->type == XR_TYPE_COMPOSITION_LAYER_PROJECTION)
        t.projection_views += reinterpret_cast<const XrCompositionLayerProjection*>(info->layers[i])->viewCount;
    t.replaced = submit != info;
    s.log.write(t);
    const std::int64_t frame = t.frame;
    t = FrameTimes{};
    t.frame = frame + 1;
  });
  return r;
}

}  // namespace fovea::layer
